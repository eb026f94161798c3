"""The browser viewer's block-compressed textures (web/src/textures/bc.js) against Python:
encoded textures made by `reliefkit.compact` (etcpak: BC7 modes 1, 5, 6, 7 from these
images; BC1, BC4, BC5; u8, u16) decode in node, through tools/viewer/run_bc.mjs, to exactly
the bytes `reliefkit.compact.encodings.decoded` gives (uint8 and float32 arrays, layers,
scale/bias, sRGB colour). BC7 modes etcpak never emits (0, 2, 3, 4, rotations, index
selection, the reserved mode) are checked twice: random blocks of every mode against
texture2ddecoder bit for bit, and hand-built blocks against the texels the BC7
specification gives them (computed here from its formulas, texture2ddecoder checked too).
`glFormatOf` is checked against the WebGL extensions' formats and the executor's rules."""

from __future__ import annotations

import base64

import numpy as np
import pytest
from node_tools import ROOT, NodeScript, unwire

from reliefkit.compact import blocks
from reliefkit.compact.encodings import EncodedImage, decoded, encode
from reliefkit.io.rk import stored_form

SCRIPT = ROOT / "tools" / "viewer" / "run_bc.mjs"


@pytest.fixture(scope="module")
def node_bc():
    script = NodeScript("the JavaScript BC decoder", SCRIPT)
    yield script
    script.close()


def js_decoded(node_bc, encoded: EncodedImage) -> np.ndarray:
    """The JS decode of ``encoded`` from what an export stores of it (bytes + record)."""
    data, record = stored_form(decoded(encoded))
    answer = node_bc.ask({"decode": {"encoding": record,
                                     "b64": base64.b64encode(data).decode()}})
    return unwire(answer)


def assert_same(node_bc, encoded: EncodedImage) -> None:
    expected = decoded(encoded)
    got = js_decoded(node_bc, encoded)
    assert got.dtype == expected.dtype and got.shape == expected.shape
    assert np.array_equal(got.view(np.uint8), expected.view(np.uint8)), \
        f"{np.count_nonzero(got != expected)} of {expected.size} values differ"


# -- images encoded by reliefkit.compact --------------------------------------------------------

def images(height: int = 37, width: int = 45) -> dict[str, np.ndarray]:
    """(H, W, 4) float images in [0, 1] (sizes not multiples of 4: the edge blocks' padding)."""
    rng = np.random.default_rng(7)
    y, x = np.mgrid[:height, :width] / np.array([height - 1, width - 1])[:, None, None]
    disc = ((x - 0.4) ** 2 + (y - 0.6) ** 2 < 0.1).astype(float)
    normal = np.stack([np.sin(7 * x) * 0.6, np.cos(5 * y) * 0.6], -1)
    normal = np.concatenate([normal, np.sqrt(1 - (normal ** 2).sum(-1, keepdims=True))], -1)
    return {
        "random": rng.random((height, width, 4)),
        "gradient": np.stack([x, y, (x + y) / 2, 1 - x * y], -1),
        "alpha_edges": np.stack([x, 1 - y, disc, disc * 0.5 + (x > 0.7) * 0.5], -1),
        "normals": np.concatenate([normal * 0.5 + 0.5, np.ones((height, width, 1))], -1),
    }


#: Format -> the channel counts it holds.
CHANNELS = {"bc1": (3, 4), "bc4": (1,), "bc5": (2,), "bc7": (3, 4), "u8": (1, 2, 3, 4),
            "u16": (1, 4)}
CASES = [(fmt, c, name) for fmt, counts in CHANNELS.items() for c in counts
         for name in images()]


def channels_of(image: np.ndarray, fmt: str, count: int) -> np.ndarray:
    out = image[..., :count].copy()
    if fmt == "bc1" and count == 4:
        out[..., 3] = 1.0  # BC1 keeps no alpha
    return out[..., 0] if count == 1 else out


@pytest.mark.parametrize("fmt, count, name", CASES, ids=[f"{f}-{c}-{n}" for f, c, n in CASES])
def test_decode_equals_python(node_bc, fmt, count, name):
    image = channels_of(images()[name], fmt, count)
    if fmt != "u16":  # uint8 arrays: the unorm bytes themselves
        assert_same(node_bc, encode(np.round(image * 255).astype(np.uint8), fmt))
    # float arrays: unorm * scale + bias in float32, and linear colour kept sRGB-encoded
    assert_same(node_bc, encode((image * 3.5 - 1.25).astype(np.float32), fmt, scale=3.5,
                                bias=-1.25))
    assert_same(node_bc, encode(image.astype(np.float32), fmt, srgb=True))


@pytest.mark.parametrize("fmt", ["bc7", "bc5", "u16"])
def test_layers_decode_equal_python(node_bc, fmt):
    count = CHANNELS[fmt][-1]
    stack = np.stack([channels_of(image, fmt, count) for image in images(12, 20).values()])
    assert_same(node_bc, encode(stack.astype(np.float32), fmt, layered=True, scale=2.0,
                                bias=0.5, mipmaps=True))


def test_every_u16_value_decodes_as_python(node_bc):
    """All 65536 unorm values, linear and sRGB (float64 powers rounded to float32)."""
    ramp = (np.arange(65536, dtype=np.float64) / 65535).reshape(256, 256)
    rgba = np.stack([ramp, ramp[::-1], ramp.T, ramp], -1).astype(np.float32)
    assert_same(node_bc, encode(rgba, "u16", srgb=True))
    assert_same(node_bc, encode(ramp.astype(np.float32), "u16", scale=0.37, bias=-0.11))


def test_wrong_byte_count_is_an_error(node_bc):
    _, record = stored_form(decoded(encode(np.zeros((8, 8, 4), np.uint8), "bc7")))
    with pytest.raises(AssertionError, match="must be 64 bytes, got 48"):
        node_bc.ask({"decode": {"encoding": record,
                                "b64": base64.b64encode(bytes(48)).decode()}})


# -- BC7: every mode --------------------------------------------------------------------------

def with_mode(data: np.ndarray, mode: int) -> np.ndarray:
    """Blocks (N, 16) whose first byte starts with ``mode``'s prefix (mode zeros, a one;
    mode 8: a zero byte, the reserved mode)."""
    out = data.copy()
    prefix = (1 << mode) if mode < 8 else 0
    out[:, 0] = (out[:, 0] & ~np.uint8((2 << mode) - 1 if mode < 8 else 255)) | prefix
    return out


@pytest.mark.parametrize("mode", range(9))
def test_random_bc7_blocks_decode_as_texture2ddecoder(node_bc, mode):
    """Any 128 bits after a mode's prefix are a block of that mode: 4096 random ones (every
    partition, rotation, index selection, P-bit) decode as texture2ddecoder decodes them."""
    data = np.random.default_rng(mode).integers(0, 256, (64 * 64, 16), dtype=np.uint8)
    encoded = EncodedImage("bc7", (256, 256, 4), "uint8", with_mode(data, mode).reshape(-1))
    assert_same(node_bc, encoded)


#: The BC7 modes (specification table): subsets, partition bits, rotation bits, index
#: selection bits, colour bits, alpha bits, P-bits per endpoint / shared per subset, index
#: bits, second index bits.
MODES = {0: (3, 4, 0, 0, 4, 0, "endpoint", 3, 0), 1: (2, 6, 0, 0, 6, 0, "shared", 3, 0),
         2: (3, 6, 0, 0, 5, 0, None, 2, 0), 3: (2, 6, 0, 0, 7, 0, "endpoint", 2, 0),
         4: (1, 0, 2, 1, 5, 6, None, 2, 3), 5: (1, 0, 2, 0, 7, 8, None, 2, 2),
         6: (1, 0, 0, 0, 7, 7, "endpoint", 4, 0), 7: (2, 6, 0, 0, 5, 5, "endpoint", 2, 0)}
WEIGHTS = {2: [0, 21, 43, 64], 3: [0, 9, 18, 27, 37, 46, 55, 64],
           4: [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64]}
#: Partitions spelled out from the specification's tables: 2 subsets #13 (top half, bottom
#: half; anchor of subset 1: texel 15), 3 subsets #8 (rows 0-1, row 2, row 3; anchors 8, 15).
PARTITION = {2: (13, "0000000011111111", [0, 15]), 3: (8, "0000000011112222", [0, 8, 15])}


def spec_block(mode: int, rotation: int, selection: int, rng) -> tuple[bytes, np.ndarray]:
    """A random block of ``mode`` (the given rotation and index selection) and its 16 RGBA
    texels as the BC7 specification decodes them."""
    subsets, pbits_n, rbits, sbits, cbits, abits, pbit_kind, ibits, i2bits = MODES[mode]
    fields: list[tuple[int, int]] = [(1 << mode, mode + 1)]
    partition, layout, anchors = PARTITION.get(subsets, (0, "0" * 16, [0]))
    fields += [(partition, pbits_n), (rotation, rbits), (selection, sbits)]
    ends = [[[0] * 4, [0] * 4] for _ in range(subsets)]
    widths = [cbits] * 3 + [abits]
    for c in range(4):
        for s in range(subsets):
            for e in range(2):
                value = int(rng.integers(0, 1 << widths[c])) if widths[c] else 0
                fields.append((value, widths[c]))
                ends[s][e][c] = value
    pbit = [[0, 0] for _ in range(subsets)]
    for s in range(subsets):
        if pbit_kind == "shared":
            pbit[s] = [int(rng.integers(0, 2))] * 2
            fields.append((pbit[s][0], 1))
        elif pbit_kind == "endpoint":
            pbit[s] = [int(rng.integers(0, 2)) for _ in range(2)]
            fields += [(p, 1) for p in pbit[s]]
    extra = 1 if pbit_kind else 0

    def unquantize(v, p, n):  # the P-bit below, then the top bits repeated below
        v, n = (v << extra) | (p if extra else 0), n + extra
        return ((v << (8 - n)) | (v >> (2 * n - 8))) & 255

    ends8 = [[[unquantize(ends[s][e][c], pbit[s][e], widths[c]) if widths[c] else 255
               for c in range(4)] for e in range(2)] for s in range(subsets)]
    subset_of = [int(d) for d in layout]
    index = [[0] * 16, [0] * 16]
    for stream, bits in ((0, ibits), (1, i2bits)):
        for t in range(16 if bits else 0):
            anchor = t == (anchors[subset_of[t]] if stream == 0 else 0)
            index[stream][t] = int(rng.integers(0, 1 << (bits - anchor)))  # top bit 0
            fields.append((index[stream][t], bits - anchor))
    value, at = 0, 0
    for v, n in fields:
        value, at = value | (v << at), at + n
    assert at == 128
    texels = np.zeros((16, 4), np.uint8)
    for t in range(16):
        colour_w = WEIGHTS[ibits][index[0][t]]
        alpha_w = WEIGHTS[i2bits][index[1][t]] if i2bits else colour_w
        if selection:
            colour_w, alpha_w = alpha_w, colour_w
        e0, e1 = ends8[subset_of[t]]
        for c in range(4):
            w = colour_w if c < 3 else alpha_w
            texels[t, c] = ((64 - w) * e0[c] + w * e1[c] + 32) >> 6
        if rotation:
            texels[t, [3, rotation - 1]] = texels[t, [rotation - 1, 3]]
    return value.to_bytes(16, "little"), texels


SPEC_CASES = [(m, r, s) for m in range(8) for r in range(4 if MODES[m][2] else 1)
              for s in range(2 if MODES[m][3] else 1)]


@pytest.mark.parametrize("mode, rotation, selection", SPEC_CASES,
                         ids=[f"mode{m}-rot{r}-sel{s}" for m, r, s in SPEC_CASES])
def test_bc7_blocks_decode_as_the_specification(node_bc, mode, rotation, selection):
    rng = np.random.default_rng(100 * mode + 10 * rotation + selection)
    made = [spec_block(mode, rotation, selection, rng) for _ in range(64)]  # a 32 x 32 image
    data = np.frombuffer(b"".join(block for block, _ in made), np.uint8)
    expected = np.stack([texels for _, texels in made]).reshape(8, 8, 4, 4, 4)
    expected = expected.transpose(0, 2, 1, 3, 4).reshape(32, 32, 4)
    assert np.array_equal(blocks.decode("bc7", data.tobytes(), 32, 32), expected)
    got = js_decoded(node_bc, EncodedImage("bc7", (32, 32, 4), "uint8", data))
    assert np.array_equal(got, expected)


def test_reserved_bc7_mode_decodes_to_zero(node_bc):
    """A first byte of 0 is the reserved mode: every channel 0 (the specification)."""
    data = with_mode(np.full((4, 16), 0xA5, np.uint8), 8).reshape(-1)
    assert not js_decoded(node_bc, EncodedImage("bc7", (8, 8, 4), "uint8", data)).any()


# -- glFormatOf ---------------------------------------------------------------------------------

S3TC, S3TC_SRGB = "WEBGL_compressed_texture_s3tc", "WEBGL_compressed_texture_s3tc_srgb"
RGTC, BPTC = "EXT_texture_compression_rgtc", "EXT_texture_compression_bptc"
ALL = [S3TC, S3TC_SRGB, RGTC, BPTC]
#: The WebGL extensions' internal formats: BC1 as opaque RGB (COMPRESSED_RGB_S3TC_DXT1_EXT,
#: COMPRESSED_SRGB_S3TC_DXT1_EXT: a three-colour block's black stays opaque, as decoded),
#: COMPRESSED_RED_RGTC1_EXT, COMPRESSED_RED_GREEN_RGTC2_EXT, COMPRESSED_RGBA_BPTC_UNORM_EXT,
#: COMPRESSED_SRGB_ALPHA_BPTC_UNORM_EXT.
LINEAR = {"bc1": 0x83F0, "bc4": 0x8DBB, "bc5": 0x8DBD, "bc7": 0x8E8C}
SRGB = {"bc1": 0x8C4C, "bc7": 0x8E8D}
NEEDS = {"bc1": S3TC, "bc4": RGTC, "bc5": RGTC, "bc7": BPTC}


def gl_format(node_bc, encoded: EncodedImage, extensions, **texture):
    _, record = stored_form(decoded(encoded))
    return node_bc.ask({"glFormat": {"encoding": record, "extensions": extensions,
                                     "texture": texture}})["format"]


def sample(fmt: str, *, size=(8, 12), dtype="uint8", srgb=False, mipmaps=False, layers=0):
    channels = CHANNELS[fmt][-1] if fmt != "bc1" else 3
    shape = (layers,) * bool(layers) + size + ((channels,) if channels > 1 else ())
    array = np.full(shape, 0.5, np.float32)
    if dtype == "uint8":
        array = np.full(shape, 128, np.uint8)
    return encode(array, fmt, srgb=srgb, mipmaps=mipmaps, layered=bool(layers))


@pytest.mark.parametrize("fmt", list(LINEAR))
def test_gl_format_where_the_extension_is(node_bc, fmt):
    encoded = sample(fmt)
    assert gl_format(node_bc, encoded, ALL) == LINEAR[fmt]
    assert gl_format(node_bc, encoded, [NEEDS[fmt]]) == LINEAR[fmt]
    assert gl_format(node_bc, encoded, [e for e in ALL if e != NEEDS[fmt]]) is None
    # sampled as sRGB: a uint8 array where its texture says so, a float one where encoded so
    for srgb_sampled in (sample(fmt), sample(fmt, dtype="float32", srgb=True)):
        texture = {"srgb": srgb_sampled.dtype == "uint8"}
        assert gl_format(node_bc, srgb_sampled, ALL, **texture) == SRGB.get(fmt)
    assert gl_format(node_bc, sample(fmt, dtype="float32"), ALL, srgb=True) == LINEAR[fmt]
    if fmt == "bc1":
        assert gl_format(node_bc, encoded, [S3TC], srgb=True) is None  # no s3tc_srgb


@pytest.mark.parametrize("fmt", list(LINEAR))
def test_gl_format_targets_sizes_and_mip_chains(node_bc, fmt):
    layered = sample(fmt, layers=3)
    assert gl_format(node_bc, layered, ALL, target="2d_array") == LINEAR[fmt]
    assert gl_format(node_bc, layered, ALL, target="3d") == (LINEAR[fmt] if fmt == "bc7"
                                                             else None)
    # WebGL takes a compressed level 0 only in multiples of 4
    assert gl_format(node_bc, sample(fmt, size=(10, 12)), ALL) is None
    # a chain the executor would upload is not stored: decoded, its mipmaps generated
    chained = sample(fmt, mipmaps=True)
    assert gl_format(node_bc, chained, ALL, mipmaps=True) is None
    assert gl_format(node_bc, chained, ALL, mipmaps=False) == LINEAR[fmt]
    assert gl_format(node_bc, sample(fmt), ALL, mipmaps=True) == LINEAR[fmt]


@pytest.mark.parametrize("fmt", ["u8", "u16"])
def test_quantized_encodings_upload_decoded(node_bc, fmt):
    assert gl_format(node_bc, sample(fmt, dtype="float32"), ALL) is None


def test_sampler_decode_follows_the_upload(node_bc):
    """A normal map's ``<sampler>_decode``: (2, -1) on its unorm blocks, (1, 0) on the
    decoded normals (executor.py sets the same)."""
    unit = images(36, 44)["normals"][..., :3].astype(np.float32)
    normals = encode(unit * 2 - 1, "bc7", scale=2.0, bias=-1.0)
    _, record = stored_form(decoded(normals))
    for extensions, expected in (([BPTC], [2.0, -1.0]), ([], [1.0, 0.0])):
        answer = node_bc.ask({"glFormat": {"encoding": record, "extensions": extensions,
                                           "texture": {}}})
        assert answer["decode"] == expected

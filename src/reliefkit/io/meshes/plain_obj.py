"""Plain OBJ files read with numpy: the common large case, in about twice the file's size.

trimesh's OBJ reader and the record-by-record checks of :mod:`.obj` hold Python strings and
match objects per line, 7 to 25 times the file in memory. A *plain* file (ASCII, every line
empty, a comment, ``v x y z``, ``vn x y z`` or a triangle ``f`` whose corners are all ``v``
or all ``v//vn`` with positive indices in range) is read here into exactly the arrays
trimesh's reader builds from it, and `PlainObj.scene_kwargs` hands them to trimesh in its own
keyword form. Anything else (materials, groups, UVs, polygons, relative or bad indices,
odd numbers) returns None and takes the general way, with its checks and messages.

The file is parsed a chunk of lines at a time (`CHUNK_BYTES`) into arrays sized by a first
counting pass, so what the parse needs beyond the file's bytes and the arrays it returns
is a few times one chunk, not a few copies of the file.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from trimesh.visual.texture import unmerge_faces

_NEWLINE, _SPACE, _SLASH = ord("\n"), ord(" "), ord("/")
_OTHER, _SKIPPED, _V, _VN, _F = range(5)  # line kinds
_BLOCK = 1 << 16  # face rows renumbered at a time


def _byte_set(chars: bytes) -> np.ndarray:
    table = np.zeros(256, bool)
    table[list(chars)] = True
    return table


_NUMBER_BYTES = _byte_set(b"0123456789.eE+- \n")
_CORNER_BYTES = _byte_set(b"0123456789/ \n")
_DIGITS = _byte_set(b"0123456789")


@dataclass
class PlainObj:
    """The arrays of a plain OBJ: positions, normals, and 0-based corners per triangle."""

    vertices: np.ndarray  # (V, 3) float64
    normals: np.ndarray | None  # (N, 3) float64, None without vn lines
    faces: np.ndarray  # (F, 3) int64 into vertices
    face_normals: np.ndarray | None  # (F, 3) int64 into normals, None for 'v' corners

    def scene_kwargs(self, name: str) -> dict:
        """What trimesh's `load_obj` returns for the file (process=False), geometry `name`.

        The arrays are handed over: this object is empty afterwards.
        """
        v, vn, faces, faces_norm = self.vertices, self.normals, self.faces, self.face_normals
        self.vertices = self.normals = self.faces = self.face_normals = None
        mesh = {"file_type": "obj", "process": False}
        if faces_norm is not None:
            faces, mask_v, mask_vn = unmerge_faces(faces, faces_norm, maintain_faces=False)
            mesh.update(faces=faces, vertices=v[mask_v], vertex_normals=vn[mask_vn])
        else:
            mesh.update(faces=faces, vertices=_only_used(v, faces))
        mesh["visual"] = None
        return {"process": False, "geometry": {name: mesh},
                "graph": [{"geometry": name, "frame_to": name}]}


#: Bytes of the file classified and parsed at a time: the temporaries of one chunk (line
#: offsets, copies of its records, token offsets, parsed numbers) are a few times this, not
#: a few times the file.
CHUNK_BYTES = 1 << 20


def _only_used(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The vertices some face uses, in order, with `faces` renumbered to them in place (as
    trimesh's reader drops unused ones); no copy when every vertex is used (the usual case)."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces] = True
    if used.all():
        return vertices
    inverse = np.cumsum(used) - 1
    for start in range(0, len(faces), _BLOCK):  # no second (F, 3) array
        faces[start:start + _BLOCK] = inverse[faces[start:start + _BLOCK]]
    return vertices[used]


def read_plain_obj(data: bytes) -> PlainObj | None:
    """The arrays of a plain OBJ file (see the module docstring), or None for any other.

    The file is read chunk by chunk twice: once to count its records, which sizes the
    arrays, then to parse each chunk's records into them; so it peaks near the file's size
    plus the arrays it returns.
    """
    if not data.isascii() or any(b in data for b in (b"\r", b"\t", b"\\", b"\0", b"+e", b"-e")):
        return None
    text = np.frombuffer(data, np.uint8)
    chunks = _chunks(data)
    counts = np.zeros(5, np.int64)  # lines of each kind
    for a, b in chunks:
        counts += np.bincount(_line_kinds(*_lines(text[a:b])), minlength=5)
    if counts[_OTHER] or not counts[_F]:
        return None
    out = PlainObj(np.empty((counts[_V], 3)),
                   np.empty((counts[_VN], 3)) if counts[_VN] else None,
                   np.empty((counts[_F], 3), np.int64), None)
    done = np.zeros(5, np.int64)  # lines of each kind parsed so far
    for a, b in chunks:
        if not _parse_chunk(text[a:b], out, done):
            return None
    if not _in_range(out.faces, len(out.vertices)):
        return None
    if out.face_normals is not None and (out.normals is None or not _in_range(
            out.face_normals, len(out.normals))):
        return None
    out.faces -= 1
    if out.face_normals is not None:
        out.face_normals -= 1
    return out


def _chunks(data: bytes) -> list[tuple[int, int]]:
    """[start, end) byte ranges of about `CHUNK_BYTES` that each end after a newline (the
    last one at the end of the file)."""
    chunks, start = [], 0
    while start < len(data):
        if start + CHUNK_BYTES >= len(data):
            end = len(data)
        else:  # after the chunk's last newline, or the next one for a line longer than it
            end = (data.rfind(b"\n", start, start + CHUNK_BYTES) + 1
                   or data.find(b"\n", start + CHUNK_BYTES) + 1 or len(data))
        chunks.append((start, end))
        start = end
    return chunks


def _lines(text: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The chunk, where its lines start and where they end (at their newline or its end)."""
    ends = np.flatnonzero(text == _NEWLINE)
    if len(text) and text[-1] != _NEWLINE:
        ends = np.append(ends, len(text))
    return text, np.concatenate([[0], ends[:-1] + 1]), ends


def _parse_chunk(text: np.ndarray, out: PlainObj, done: np.ndarray) -> bool:
    """Parse one chunk's v, vn and f lines into `out` after the `done` ones (updated);
    False when a record is not plain."""
    text, starts, ends = _lines(text)
    kinds = _line_kinds(text, starts, ends)
    for kind, target in ((_V, out.vertices), (_VN, out.normals)):
        chosen = kinds == kind
        if chosen.any():
            values = _numbers(text, starts, chosen, 1 if kind == _V else 2)
            if values is None:
                return False
            target[done[kind]:done[kind] + len(values)] = values
            done[kind] += len(values)
    chosen = kinds == _F
    if not chosen.any():
        return True
    corners = _corners(text, starts, chosen)
    if corners is None:
        return False
    faces, face_normals = corners
    first = done[_F] == 0
    if first and face_normals is not None:
        out.face_normals = np.empty_like(out.faces)
    if (face_normals is None) != (out.face_normals is None):  # 'v' and 'v//vn' faces mixed
        return False
    rows = slice(done[_F], done[_F] + len(faces))
    out.faces[rows] = faces
    if face_normals is not None:
        out.face_normals[rows] = face_normals
    done[_F] += len(faces)
    return True


def _line_kinds(text: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Each line's kind: skipped (empty or a comment), v, vn, f or other."""
    def byte(offset: int) -> np.ndarray:
        at = np.minimum(starts + offset, len(text) - 1)
        return np.where(starts + offset < ends, text[at], _NEWLINE)

    first, second, third = byte(0), byte(1), byte(2)
    kinds = np.full(len(starts), _OTHER, np.uint8)
    kinds[(first == _NEWLINE) | (first == ord("#"))] = _SKIPPED
    kinds[(first == ord("v")) & (second == _SPACE)] = _V
    kinds[(first == ord("v")) & (second == ord("n")) & (third == _SPACE)] = _VN
    kinds[(first == ord("f")) & (second == _SPACE)] = _F
    return kinds


def _contents(text: np.ndarray, starts: np.ndarray, chosen: np.ndarray, keyword: int) -> np.ndarray:
    """The chosen lines with their newlines, the `keyword` bytes blanked to spaces."""
    lengths = np.diff(np.append(starts, len(text)))  # each line with its newline
    content = _runs(text, starts, lengths, chosen)
    kept = lengths[chosen]
    first = np.cumsum(kept) - kept  # where each chosen line starts in `content`
    for k in range(keyword):
        content[first + k] = _SPACE
    return content


def _runs(text: np.ndarray, starts: np.ndarray, lengths: np.ndarray,
          chosen: np.ndarray) -> np.ndarray:
    """The bytes of the chosen lines, copied run by run of consecutive chosen lines (files
    group their records, so there are few runs) rather than through a file-sized mask."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], chosen.view(np.int8), [0]])))
    first, last = edges[0::2], edges[1::2]  # runs of chosen lines [first, last)
    if len(first) > 1024:
        return text[np.repeat(chosen, lengths)]
    ends = starts[last - 1] + lengths[last - 1]
    return np.concatenate([text[a:b] for a, b in zip(starts[first], ends, strict=True)])


def _tokens(content: np.ndarray, lines: int, per_line: int) -> np.ndarray | None:
    """Where each whitespace-separated token starts, when every line has `per_line`."""
    blank = _blank(content)
    starts = np.flatnonzero(blank[:-1] > blank[1:]) + 1  # a blank, then a non-blank
    del blank
    if len(content) and content[0] > _SPACE:
        starts = np.concatenate([[0], starts])
    ended = np.searchsorted(starts, np.flatnonzero(content == _NEWLINE))  # tokens before
    if len(starts) != lines * per_line or (np.diff(ended, prepend=0) != per_line).any():
        return None
    return starts


def _blank(content: np.ndarray) -> np.ndarray:
    """Spaces and newlines: the only bytes at or below a space in checked content."""
    return content <= _SPACE


def _parsed(content: np.ndarray, dtype) -> np.ndarray:
    """The numbers of `content`; none (a count the callers refuse) where one cannot be read.

    numpy stops early with a warning (older versions) or raises ValueError (2.x)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return np.fromstring(content.tobytes(), dtype=dtype, sep=" ")
        except ValueError:
            return np.empty(0, dtype)


def _numbers(text, starts, chosen, keyword: int) -> np.ndarray | None:
    """(n, 3) float64 of the chosen lines, each exactly three numbers; else None."""
    content = _contents(text, starts, chosen, keyword)
    lines = int(chosen.sum())
    if not _NUMBER_BYTES[content].all() or _tokens(content, lines, 3) is None:
        return None
    values = _parsed(content, np.float64)
    return values.reshape(lines, 3) if len(values) == 3 * lines else None


def _corners(text, starts, chosen) -> tuple[np.ndarray, np.ndarray | None] | None:
    """1-based (F, 3) vertex and normal indices of triangles whose corners are all 'v' or
    all 'v//vn'; None for anything else."""
    content = _contents(text, starts, chosen, 1)
    lines = int(chosen.sum())
    if not _CORNER_BYTES[content].all():
        return None
    corners = _tokens(content, lines, 3)
    if corners is None:
        return None
    slashes = np.flatnonzero(content == _SLASH)
    if len(slashes) not in (0, 2 * len(corners)):
        return None
    fields = 1
    if len(slashes):
        per_corner = np.bincount(np.searchsorted(corners, slashes, side="right") - 1,
                                 minlength=len(corners))
        pairs = int((content[slashes[:-1] + 1] == _SLASH).sum())
        blank = _blank(content)
        last = np.flatnonzero(blank[:-1] < blank[1:])  # a token's last byte, then a blank
        del blank
        if content[-1] > _SPACE:
            last = np.append(last, len(content) - 1)
        if (per_corner != 2).any() or pairs != len(corners) \
                or not _DIGITS[content[corners]].all() or not _DIGITS[content[last]].all():
            return None
        content[slashes] = _SPACE
        fields = 2
    values = _parsed(content, np.int64)
    if len(values) != 3 * fields * lines:
        return None
    values = values.reshape(lines, 3 * fields)
    if fields == 1:
        return values, None
    return np.ascontiguousarray(values[:, 0::2]), np.ascontiguousarray(values[:, 1::2])


def _in_range(indices: np.ndarray, count: int) -> bool:
    return bool(indices.size) and int(indices.min()) >= 1 and int(indices.max()) <= count

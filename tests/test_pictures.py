"""Contact sheets: every caption stays within its own tile's width and on the sheet."""

import numpy as np

from reliefkit.pictures import SHEET_BACKGROUND, contact_sheet

TILE, PAD = 96, 8


def test_long_captions_wrap_within_their_tile():
    """Captions as long as compare's at 192 px ('unlit, centroid sort: error, wrong in red')
    and the demo's last column: nothing is drawn in the gaps between tiles or past the
    sheet's right edge, and the tiles themselves are pasted whole."""
    colours = [(200, 60, 40), (40, 160, 60), (50, 80, 200), (180, 160, 40)]
    tiles = [(caption, np.full((TILE, TILE, 4), (*rgb, 255), np.uint8)) for caption, rgb in
             zip(["unlit, centroid sort: error, wrong in red", "mesh",
                  "displacement: bumps, orthogonal slicing",
                  "averyveryverylongwordwithoutanyspacesatall"], colours, strict=True)]
    sheet = np.asarray(contact_sheet(tiles, columns=4))
    background = np.all(sheet == SHEET_BACKGROUND, axis=-1)
    cell = TILE + PAD
    for k in range(5):  # the gap left of each tile and right of the last
        gap = background[:, k * cell:k * cell + PAD]
        assert gap.all(), f"something drawn in gap {k}"
    for k, rgb in enumerate(colours):  # each tile whole, at the bottom of its cell
        block = sheet[-PAD - TILE:-PAD, PAD + k * cell:PAD + k * cell + TILE]
        assert np.all(block == rgb), k


def test_a_long_path_breaks_after_its_separators():
    """A batch sheet's caption (an output's path) broke mid-name: 'glTF2/2CylinderEng' +
    'ine-glTF-Binary/...'; every piece now ends at a '/', '-', '_' or '.' where one fits,
    and the pieces put together are the text."""
    from PIL import ImageFont

    from reliefkit.pictures import wrap_text

    font = ImageFont.load_default()
    text = "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine: relief-cube"
    width = TILE * 1.3
    lines = wrap_text(text, font, width)
    assert len(lines) > 2 and all(font.getlength(line) <= width for line in lines)
    assert " ".join(lines).replace("/ ", "/").replace("- ", "-") == text
    assert all(line[-1] in "/-_.:" or line == lines[-1] for line in lines), lines

"""The built-in techniques, listed explicitly: the only module that names them all.

Adding a technique means one new package beside these and one entry here.
"""

from .billboard import TECHNIQUE as BILLBOARD
from .impostor import TECHNIQUE as IMPOSTOR
from .relief import TECHNIQUE as RELIEF
from .shellvolume import TECHNIQUE as SHELLVOLUME
from .slicing import TECHNIQUE as SLICING

TECHNIQUES = (RELIEF, BILLBOARD, SHELLVOLUME, SLICING, IMPOSTOR)

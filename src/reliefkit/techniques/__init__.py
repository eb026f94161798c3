"""The built-in techniques, listed explicitly: the only module that names them all.

Adding a technique means one new package beside these and one entry here.
"""

from .relief import TECHNIQUE as RELIEF

TECHNIQUES = (RELIEF,)

"""reliefkit: render geometry from textures with depth."""

from .errors import FormatError, GPUError, MeshError, ReliefkitError, UsageError

__all__ = ["ReliefkitError", "MeshError", "FormatError", "GPUError", "UsageError"]
__version__ = "0.1.0"

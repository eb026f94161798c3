"""The exceptions reliefkit raises: one base class, one subclass per kind of failure.

Every message says what was wrong and, where it can, what to do about it; the CLI prints
it as a single ``error: ...`` line.
"""


class ReliefkitError(Exception):
    """Base class of every error reliefkit raises on purpose."""


class MeshError(ReliefkitError):
    """A mesh could not be read, or it is empty, non-finite or has bad indices."""


class FormatError(ReliefkitError):
    """A .rk file (or another input file) is malformed, forged, truncated or unsupported."""


class GPUError(ReliefkitError):
    """No OpenGL context, a shader failed to compile, or a request exceeds a GL limit."""


class UsageError(ReliefkitError):
    """An argument is out of range or inconsistent (a bad view, size, method, ...)."""

"""`GLObjects`: what a drawable owns on the GPU, released in reverse order (also when its
upload fails half way, so a refused texture never leaks the buffers made before it)."""

from __future__ import annotations


class GLObjects:
    """Mixin of drawables: ``_upload_owned(upload)`` runs ``upload()`` and releases everything
    kept so far if it raises; ``keep(obj)`` records an object; ``release()`` frees them."""

    def _upload_owned(self, upload) -> None:
        self._objects: list = []
        try:
            upload()
        except BaseException:
            self.release()
            raise

    def keep(self, obj):
        self._objects.append(obj)
        return obj

    def release(self) -> None:
        for obj in reversed(getattr(self, "_objects", [])):
            obj.release()
        self._objects = []

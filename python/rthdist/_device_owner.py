"""What rthdist.Engine and rthdist.MaskEngine share: a compiled engine held in
``self._engine`` that owns a device (or the CPU backend), its backend and
device names, and its release (``close``, ``with``)."""


class DeviceOwner:
    """Base of the Python engines: ``self._engine`` is the compiled object
    (``backend``, ``device``, ``closed``, ``close``)."""

    @property
    def backend(self):
        """The backend this engine runs: "cpu", "ray-query" or "rt-pipeline"."""
        return self._engine.backend

    @property
    def device(self):
        """Its device's name ("cpu" for the CPU backend)."""
        return self._engine.device

    @property
    def closed(self):
        return self._engine.closed

    def close(self):
        """Releases the device now (idempotent)."""
        self._engine.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        name = type(self).__name__
        if self.closed:
            return f"{name}(closed)"
        return f"{name}(backend={self.backend!r}, device={self.device!r})"

"""glTF 2.0 files: the deterministic GLB container (`glb`) the exporter writes and reads, and
a `RenderMesh` as core glTF (`mesh`), what any viewer shows."""

"""glTF 2.0 files: the deterministic GLB container (`glb`) the exporter writes and reads."""

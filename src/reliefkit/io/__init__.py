"""Files: the .rk container (`rk`), the mesh kind, the one atomic writer, opening inputs."""

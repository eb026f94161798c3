"""Files: the .rk container (`rk`), the mesh kind, the mesh files (`meshes`), the one atomic
writer, opening inputs."""

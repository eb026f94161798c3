"""Shell volumes (Dufort, Leblanc & Poulin 2005): a 3D texture tiled in a layer of prisms
extruded from a mesh, each prism split into three tetrahedra.

Not a registered technique yet; `shell.build_shell` builds the shell's geometry (issue 10).
"""

"""Displacement slicing and image-based depth objects (Kautz & Seidel), in progress.

Not registered as a technique yet (`reliefkit.techniques.TECHNIQUES` does not list it):
so far it holds the six depth images of a mesh on its bounding cube (`depth_images`) and
the exact CPU reference for the object they define (`reference`), and the slice polygons of
the paper's three slicing modes (`slices`: surface-aligned, orthogonal, screen-space).
"""

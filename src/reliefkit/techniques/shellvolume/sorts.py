"""The visibility sorts `order.visibility_order` offers, light to import: the render options
(and with them the command line's help) name them without loading the numba-compiled sort."""

METHODS = ("sxmpvo", "centroid")

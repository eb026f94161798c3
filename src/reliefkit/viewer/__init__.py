"""`reliefkit view`: representations drawn in the browser by the shaders the offscreen
renderer uses (docs/viewer.md).

`site.py` makes the static site (the page, the bundled executor, one GLB per input with its
draw plans and GLSL ES sources, inputs.json); `server.py` serves it on 127.0.0.1 and logs
the errors the page posts. The page's sources are in web/src/ (bundled by web/build.mjs).
"""

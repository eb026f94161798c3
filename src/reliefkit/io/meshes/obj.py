"""OBJ text before trimesh parses it: face corners checked, concave polygons triangulated.

Lines continued with a trailing backslash are joined. Every face corner is checked against
the v/vt/vn it refers to; references to texture coordinates or normals that the file does not
define at all are dropped with a warning (as common importers read such files). trimesh
splits polygons into fans (quads along the diagonal from their first corner), which is wrong
for concave ones, so those faces are rewritten as the triangles of an ear clipping, corners
kept verbatim.
"""

from __future__ import annotations

import re

import numpy as np

from .badfile import BadFile, decode_text
from .polygons import triangulate_polygon

_CONTINUATION = re.compile(r"\\[ \t]*\r?\n")  # a backslash ending a line continues it
# OBJ records that define or use indices: (keyword, rest of the line without its comment)
_OBJ_RECORD = re.compile(r"(?m)^[ \t]*(vt|vn|v|f)[ \t]+([^\n#]*)")

# what the index in each field of a face corner v/vt/vn is called, and what it counts
_OBJ_SLOTS = {
    "v": ("face index", "vertices"),
    "vt": ("face texture-coordinate index", "texture coordinates"),
    "vn": ("face normal index", "normals"),
}


def check_obj(data: bytes, notes: list[str] | None = None) -> bytes:
    """Check every face corner of an OBJ against the v/vt/vn it defines; warnings (dropped
    references) are appended to ``notes``."""
    text = _CONTINUATION.sub(" ", decode_text(data, "OBJ"))
    matches = list(_OBJ_RECORD.finditer(text))
    records = [m.groups() for m in matches]
    kinds = [kind for kind, _ in records]
    totals = {slot: kinds.count(slot) for slot in _OBJ_SLOTS}
    fields = _obj_face_fields(" ".join(rest for kind, rest in records if kind == "f"))
    undefined = [slot for slot in ("vt", "vn") if fields.get(slot) and not totals[slot]]
    if undefined:
        text = _without_slots(text, matches, undefined)
        for slot in undefined:
            if notes is not None:
                notes.append(f"its faces refer to {_OBJ_SLOTS[slot][1]}, but it defines none; "
                             "those references are ignored")
        return check_obj(text.encode("utf-8"), notes)
    for slot, values in fields.items():
        indices = _integers(values)
        if (indices < 0).any():  # relative indices depend on what precedes each face
            _check_obj_relative(records, totals)
            break
        bad = indices[(indices < 1) | (indices > totals[slot])]
        if bad.size:
            _check_obj_index(str(bad[0]), slot, totals[slot], totals[slot])
    return _triangulated(text, matches, totals["v"]).encode("utf-8")


def _without_slots(text: str, matches: list[re.Match], slots: list[str]) -> str:
    """`text` with the vt and/or vn fields of every face corner removed."""
    drop = [list(_OBJ_SLOTS).index(slot) for slot in slots]
    pieces, end = [], 0
    for match in matches:
        if match.group(1) != "f":
            continue
        corners = []
        for corner in match.group(2).split():
            fields = corner.split("/") + [""] * 2
            for k in drop:
                fields[k] = ""
            v, vt, vn = fields[:3]
            corners.append(v + (f"/{vt}/{vn}" if vn else f"/{vt}" if vt else ""))
        pieces += [text[end:match.start(2)], " ".join(corners)]
        end = match.end(2)
    return "".join(pieces) + text[end:]


def _obj_face_fields(faces: str) -> dict[str, list[str]]:
    """The non-empty v, vt and vn fields of the face corners ('v', 'v/vt', 'v//vn', ...)."""
    corners = faces.split()
    if "/" not in faces:
        return {"v": corners}
    fields = [corner.split("/") for corner in corners]
    return {
        "v": [f[0] for f in fields],
        "vt": [f[1] for f in fields if len(f) > 1 and f[1]],
        "vn": [f[2] for f in fields if len(f) > 2 and f[2]],
    }


def _integers(fields: list[str]) -> np.ndarray:
    try:
        return np.array(list(map(int, fields)), dtype=np.int64)
    except ValueError as exc:
        raise BadFile(f"malformed index ({exc})") from None
    except OverflowError:
        raise BadFile("has an index too large to be real") from None


def _check_obj_relative(records: list[tuple[str, str]], totals: dict[str, int]) -> None:
    """Face corners one by one, resolving negative indices against the records before them."""
    seen = dict.fromkeys(totals, 0)
    for kind, rest in records:
        if kind != "f":
            seen[kind] += 1
            continue
        for corner in rest.split():
            for slot, field in zip(_OBJ_SLOTS, corner.split("/"), strict=False):
                if field:
                    _check_obj_index(field, slot, seen[slot], totals[slot])


def _check_obj_index(field: str, slot: str, seen: int, total: int) -> None:
    """One OBJ face index: 1-based absolute, or negative and relative to the `seen` so far."""
    try:
        index = int(field)
    except ValueError:
        raise BadFile(f"malformed face entry '{field}' (expected an integer)") from None
    kind, noun = _OBJ_SLOTS[slot]
    if index == 0 or index > total or index < -seen:
        hint = " (OBJ indices start at 1)" if index == 0 else ""
        raise BadFile(f"{kind} {index} out of range for {total} {noun}{hint}")
    if index < 0 and seen != total:
        raise BadFile(
            f"uses relative (negative) indices before all {noun} are defined, which the "
            "reader (trimesh) resolves wrongly; re-export it with absolute indices"
        )


def _triangulated(text: str, matches: list[re.Match], vertex_count: int) -> str:
    """`text` with each face that a fan would get wrong replaced by ear-clipped triangles."""
    faces = [(m, m.group(2).split()) for m in matches if m.group(1) == "f"]
    faces = [(m, corners) for m, corners in faces if len(corners) > 3]
    if not faces:
        return text
    try:
        positions = np.array(
            [m.group(2).split()[:3] for m in matches if m.group(1) == "v"], dtype=np.float64)
        corner_vertices = [[_vertex_index(c, vertex_count) for c in corners]
                           for _, corners in faces]
    except ValueError:  # ragged or odd vertex records: leave them to trimesh
        return text
    quads = [k for k, (_, corners) in enumerate(faces) if len(corners) == 4]
    fan_ok = np.zeros(len(faces), bool)
    if quads:
        fan_ok[quads] = _first_diagonal_inside(positions[[corner_vertices[k] for k in quads]])
    pieces, end = [], 0
    for (match, corners), vertices, ok in zip(faces, corner_vertices, fan_ok, strict=True):
        if ok:
            continue
        triangles = triangulate_polygon(positions[vertices])
        pieces += [text[end:match.start()],
                   "\n".join("f " + " ".join(corners[i] for i in t) for t in triangles)]
        end = match.end()
    return "".join(pieces) + text[end:]


def _vertex_index(corner: str, count: int) -> int:
    """The 0-based vertex of a face corner 'v', 'v/vt', 'v//vn' or 'v/vt/vn' (checked before)."""
    index = int(corner.split("/")[0])
    return index - 1 if index > 0 else count + index


def _first_diagonal_inside(quads: np.ndarray) -> np.ndarray:
    """Per (Q, 4, 3) quad: is the diagonal 0-2, which trimesh splits along, inside it?

    It is unless corners 1 and 3 lie on the same side of it (a concave quad whose reflex
    corner is 1 or 3). Polygons of five or more corners are always ear clipped.
    """
    p0, p1, p2, p3 = (quads[:, i] for i in range(4))
    normal = np.cross(p2 - p0, p3 - p1)  # the quad's vector area, doubled
    side1 = np.einsum("ij,ij->i", np.cross(p2 - p0, p1 - p0), normal)
    side3 = np.einsum("ij,ij->i", np.cross(p2 - p0, p3 - p0), normal)
    return side1 * side3 <= 0

"""The structural check of OBJ files: every face corner against the v/vt/vn it refers to."""

from __future__ import annotations

import re

import numpy as np

from .badfile import BadFile, decode_text

# OBJ records that define or use indices: (keyword, rest of the line without its comment)
_OBJ_RECORD = re.compile(r"(?m)^[ \t]*(vt|vn|v|f)[ \t]+([^\n#]*)")

# what the index in each field of a face corner v/vt/vn is called, and what it counts
_OBJ_SLOTS = {
    "v": ("face index", "vertices"),
    "vt": ("face texture-coordinate index", "texture coordinates"),
    "vn": ("face normal index", "normals"),
}


def check_obj(data: bytes) -> bytes:
    """Check every face corner of an OBJ against the v/vt/vn it defines."""
    text = decode_text(data, "OBJ").replace("\\\n", "")
    records = _OBJ_RECORD.findall(text)
    kinds = [kind for kind, _ in records]
    totals = {slot: kinds.count(slot) for slot in _OBJ_SLOTS}
    fields = _obj_face_fields(" ".join(rest for kind, rest in records if kind == "f"))
    for slot, values in fields.items():
        indices = _integers(values)
        if (indices < 0).any():  # relative indices depend on what precedes each face
            _check_obj_relative(records, totals)
            break
        bad = indices[(indices < 1) | (indices > totals[slot])]
        if bad.size:
            _check_obj_index(str(bad[0]), slot, totals[slot], totals[slot])
    return text.encode("utf-8")


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

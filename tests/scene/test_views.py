"""The CLI's view arguments: --view, --size, --fov parsed and checked with the flag named."""

from __future__ import annotations

import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.views import check_fov, parse_size, parse_view


def test_negative_angles_parse():
    assert parse_view("-30,20") == (-30.0, 20.0, None)
    assert parse_view("-30,-20,3") == (-30.0, -20.0, 3.0)


@pytest.mark.parametrize("text", ["1", "1,2,3,4", "a,b", "0,90", "0,10,-1", "nan,0"])
def test_bad_views(text):
    with pytest.raises(UsageError, match="--view"):
        parse_view(text)


@pytest.mark.parametrize("fov", [0.0, 180.0, -5.0, float("nan")])
def test_bad_fov(fov):
    with pytest.raises(UsageError, match="--fov"):
        check_fov(fov)


def test_size():
    assert parse_size("64x32") == (64, 32)
    with pytest.raises(UsageError, match="--size"):
        parse_size("0x5")

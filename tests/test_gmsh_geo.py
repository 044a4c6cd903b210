"""A broken ``.geo`` file is one InputError naming the file (and line), and spoils nothing after it."""
import re

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh")

from rkfx.errors import InputError  # noqa: E402
from rkfx.geometry.gmsh_nodes import from_geo  # noqa: E402

POINTS = """Point(1) = {0, 0, 0, 0.5};
Point(2) = {1, 0, 0, 0.5};
Point(3) = {1, 1, 0, 0.5};
Point(4) = {0, 1, 0, 0.5};
"""
SQUARE = POINTS + """Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Surface("domain") = {1};
"""
# Line 3 misses a comma; the statements after it are what gmsh used to leave in its lexer.
SYNTAX = POINTS.replace("{1, 1, 0, 0.5}", "{1, 1, 0 0.5}") + "Line(1) = {1, 2};\n"
# Three lines do not close the square.
UNCLOSED = POINTS + """Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
"""
# Point 7 is never defined; line 6 is the first to use it.
UNDEFINED = SQUARE.replace("{2, 3};\nLine(3) = {3, 4}", "{2, 7};\nLine(3) = {7, 4}")


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text)
    return path


def _error(path) -> str:
    with pytest.raises(InputError) as info:
        from_geo(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    return message


BROKEN = [  # file name, contents, what the message says after the name
    ("syntax.geo", SYNTAX, r":3: syntax error .*fix the file"),
    ("unclosed.geo", UNCLOSED, r": gmsh cannot mesh it: .*closed loop.*fix the file"),
    ("undefined.geo", UNDEFINED, r":6: .*control point 7.*fix the file"),
    ("empty.geo", "", r": the file is empty, so it defines no surface"),
    ("blank.geo", "\n  \n", r": the file is empty"),
    ("comments.geo", "// nothing yet\n", r": the file defines no surface; add a Plane Surface"),
    ("binary.geo", b"\x00\x01PK\x03\x04\xff\xfe", r": not a \.geo text file"),
]


@pytest.mark.parametrize("name, text, expected", [pytest.param(*b, id=b[0][:-4]) for b in BROKEN])
def test_broken_file_names_the_file_and_line(tmp_path, name, text, expected):
    path = _write(tmp_path, name, text)
    assert re.search(re.escape(str(path)) + expected, _error(path))


@pytest.mark.parametrize("bad", [SYNTAX, UNCLOSED, UNDEFINED], ids=["syntax", "unclosed", "undefined"])
@pytest.mark.parametrize("session", ["own", "caller's"])
def test_good_file_after_a_broken_one_gives_the_same_nodes(tmp_path, bad, session):
    good = _write(tmp_path, "square.geo", SQUARE)
    broken = _write(tmp_path, "broken.geo", bad)
    if session == "caller's":
        gmsh.initialize(interruptible=False)
        abort = gmsh.option.getNumber("General.AbortOnError")
    try:
        before = from_geo(good)
        with pytest.raises(Exception):  # noqa: B017, PT011 - the messages are tested above
            from_geo(broken)
        after = from_geo(good)
        if session == "caller's":
            # The caller's options come back as they were.
            assert gmsh.option.getNumber("General.AbortOnError") == abort
    finally:
        if session == "caller's":
            gmsh.finalize()
    np.testing.assert_array_equal(after.x, before.x)
    np.testing.assert_array_equal(after.triangles, before.triangles)
    assert set(after.boundary_names) == {"bottom"}
    assert after.area() == pytest.approx(1.0)


class _OtherRank:
    """Rank 1 of 2: what rank 0 broadcasts is handed in."""

    rank, size = 1, 2

    def __init__(self, sent):
        self.sent = sent

    def bcast(self, data, root=0):
        return self.sent


def test_every_rank_raises_rank_0s_error(tmp_path):
    path = _write(tmp_path, "syntax.geo", SYNTAX)
    sent = InputError(f"{path}:3: syntax error (0.5); fix the file and call from_geo again")
    with pytest.raises(InputError, match=":3: syntax error"):
        from_geo(path, comm=_OtherRank(sent))

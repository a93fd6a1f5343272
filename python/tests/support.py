"""Helpers of the Python server's unit tests: the package on sys.path and meshes from .geo text."""

import os
import pathlib
import sys
import tempfile

PYTHON_DIRECTORY = pathlib.Path(__file__).resolve().parent.parent
REPOSITORY = PYTHON_DIRECTORY.parent
TEST_DATA = REPOSITORY / "tests" / "data"
sys.path.insert(0, str(PYTHON_DIRECTORY))

from robin_subdomain import mesh as mesh_reader  # noqa: E402

# Rectangle [0, 2] x [0, 1] with an off-centre interior point, so that the mesh is irregular.
RECTANGLE_GEO = """
DefineConstant[ h = 0.4 ];
Point(1) = {0, 0, 0, h};
Point(2) = {2, 0, 0, h};
Point(3) = {2, 1, 0, h};
Point(4) = {0, 1, 0, h};
Point(5) = {0.63, 0.41, 0, h / 3};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point{5} In Surface{1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("body") = {1};
"""


def mesh_from_geo(text, size=0.0, element_order=1, recombine=False):
    """The mesh of .geo `text`, meshed by the gmsh command-line tool."""
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "test.geo")
        with open(path, "w") as stream:
            stream.write(text)
        return mesh_reader.read_mesh(path, "test.geo", size, element_order, recombine)

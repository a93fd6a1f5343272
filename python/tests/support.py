"""Helpers of the Python server's unit tests: the package on sys.path, meshes from .geo text and
from the repository's .msh files, MeshData and AssignContact messages (protocol 2.0), and an
independent P1 stiffness for checks that must not reuse the code under test."""

import os
import pathlib
import sys
import tempfile

import numpy as np

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

CELL_TYPE_NAMES = {mesh_reader.TRIANGLE3: "TRIANGLE3", mesh_reader.TRIANGLE6: "TRIANGLE6",
                   mesh_reader.QUADRILATERAL4: "QUADRILATERAL4", mesh_reader.LINE2: "LINE2",
                   mesh_reader.LINE3: "LINE3"}


def mesh_from_geo(text, size=0.0, element_order=1, recombine=False):
    """The mesh of .geo `text`, meshed by the gmsh command-line tool."""
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "test.geo")
        with open(path, "w") as stream:
            stream.write(text)
        return mesh_reader.read_mesh(path, "test.geo", size, element_order, recombine)


def _cell_block(protocol, target, cell_type, connectivity):
    target.type = protocol.CellType.Value(CELL_TYPE_NAMES[cell_type])
    target.connectivity.extend(int(node) for node in np.ravel(connectivity))


def mesh_data(protocol, mesh, source):
    """The MeshData message of a Mesh (node tags, cells as they are, named boundaries); cell
    tags 1, 2, ... per block (so that messages name them)."""
    message = protocol.MeshData(dimension=2, source=source)
    message.coordinates.extend(mesh.nodes.ravel().tolist())
    message.node_tags.extend(int(tag) for tag in mesh.node_tags)
    for block in mesh.blocks:
        cells = message.cells.add()
        _cell_block(protocol, cells, block.type, block.connectivity)
        cells.tags.extend(range(1, len(block.connectivity) + 1))
    for name, group in sorted(mesh.boundaries.items()):
        boundary = message.boundaries.add(name=name)
        _cell_block(protocol, boundary.segments, group.type, group.connectivity)
    return message


def mesh_data_from_msh(protocol, file_name):
    """The MeshData of tests/data/<file_name>, read with the package's .msh reader."""
    mesh = mesh_reader.read_mesh(TEST_DATA / file_name, file_name)
    return mesh_data(protocol, mesh, file_name)


def node_to_node_assignment(protocol, interface):
    """The AssignContact of node-to-node contact on every node of an InterfaceDescription: one
    row per node with the components of its normal, weighted by the node's boundary weight."""
    count = len(interface.node_ids)
    return protocol.AssignContact(
        row_offsets=range(0, 2 * count + 1, 2), node_ids=np.repeat(interface.node_ids, 2),
        components=[0, 1] * count, values=interface.normals, weights=interface.weights)


def sparse_rows(protocol, rows):
    """AssignContact of rows [(weight, [(node id, component, value), ...]), ...]."""
    message = protocol.AssignContact(row_offsets=[0])
    for weight, entries in rows:
        for node, component, value in entries:
            message.node_ids.append(node)
            message.components.append(component)
            message.values.append(value)
        message.row_offsets.append(len(message.values))
        message.weights.append(weight)
    return message


def p1_stiffness(nodes, triangles, elasticity):
    """K (2n x 2n, dense) of linear triangles, assembled here independently of the package:
    K_e = area B' C B with the constant strain-displacement matrix of each triangle."""
    stiffness = np.zeros((2 * len(nodes), 2 * len(nodes)))
    for triangle in triangles:
        (x1, y1), (x2, y2), (x3, y3) = nodes[triangle]
        twice_area = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
        b = np.array([y2 - y3, y3 - y1, y1 - y2]) / twice_area    # dN/dx
        c = np.array([x3 - x2, x1 - x3, x2 - x1]) / twice_area    # dN/dy
        strain = np.zeros((3, 6))
        strain[0, 0::2], strain[1, 1::2] = b, c
        strain[2, 0::2], strain[2, 1::2] = c, b
        dofs = np.ravel([[2 * node, 2 * node + 1] for node in triangle])
        stiffness[np.ix_(dofs, dofs)] += 0.5 * twice_area * strain.T @ elasticity @ strain
    return stiffness


def p1_body_force(nodes, triangles, force):
    """Consistent nodal load of a constant body force on linear triangles: a third of each
    triangle's area times the force at each of its corners."""
    load = np.zeros((len(nodes), 2))
    for triangle in triangles:
        (x1, y1), (x2, y2), (x3, y3) = nodes[triangle]
        area = 0.5 * abs((x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1))
        load[triangle] += area / 3.0 * np.asarray(force)
    return load.ravel()


def plane_strain_elasticity(young, poisson):
    """The plane-strain Voigt stiffness, written out here (not the package's)."""
    factor = young / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
    return factor * np.array([[1.0 - poisson, poisson, 0.0], [poisson, 1.0 - poisson, 0.0],
                              [0.0, 0.0, 0.5 - poisson]])


def hostile_geo_scripts(witness):
    """The Gmsh script attacks of issue 11 (tests/hostile_geo_scripts.hpp holds the same list),
    as (label, .geo text to append to a valid script) pairs. Each is live under Gmsh 4: the
    command ones run `touch witness`, ListFromFile prints the lines of /etc/passwd and
    CurrentDirectory the script's directory. Five bypassed the keyword filter of the 1.x
    servers: a backslash in a double-quoted string, single-quoted 'a"', '/*' and '//', a NUL in
    a // comment."""
    touch = 'SystemCall "touch %s";' % witness
    return [
        ("SystemCall", "\n%s\n" % touch),
        ("ExternalProcess", '\nField[1] = ExternalProcess;\nField[1].CommandLine = "touch %s";'
                            '\nBackground Field = 1;\n' % witness),
        ("backslash in a double-quoted string", '\ns = "a\\"; %s // "\n' % touch),
        ("single-quoted 'a\"'", "\nx = 'a\"';\n%s\n// \"\n" % touch),
        ("single-quoted '/*'", "\nx = '/*';\n%s\nx = '*/';\n" % touch),
        ("single-quoted '//'", "\nx = '//'; %s\n" % touch),
        ("NUL in a // comment", "\n// comment\0 %s\n" % touch),
        ("ListFromFile /etc/passwd",
         '\nx[] = ListFromFile("/etc/passwd");\nError("leak %g", x[0]);\n'),
        ("CurrentDirectory", '\nError(StrCat("cwd ", CurrentDirectory));\n'),
    ]


def _varint(value):
    data = bytearray()
    while value >= 0x80:
        data.append((value & 0x7F) | 0x80)
        value >>= 7
    data.append(value)
    return bytes(data)


def _length_delimited(number, payload):
    return _varint(number << 3 | 2) + _varint(len(payload)) + payload


def with_1x_script(envelope_bytes, script):
    """`envelope_bytes` (a SetupBody request) followed by, written by hand, the 1.x fields 2
    (mesh_content) = `script` and 3 (mesh_extension) = ".geo" of Envelope.setup_body (field 12;
    protobuf merges the two occurrences), as a 1.x coordinator sent a .geo body."""
    return envelope_bytes + _length_delimited(
        12, _length_delimited(2, script.encode()) + _length_delimited(3, b".geo"))


def passwd_lines():
    """The non-empty lines of /etc/passwd (none when it cannot be read)."""
    try:
        with open("/etc/passwd", encoding="utf-8", errors="replace") as stream:
            return [line.rstrip("\n") for line in stream if line.strip()]
    except OSError:
        return []


# Solid meshes (protocol 2.4), built here independently of the package.

def _box_grid(cells, lengths, perturbation):
    """Nodes (n x 3) of a (cells + 1) grid on the box [0, L]; interior nodes moved by
    `perturbation` cell widths along a fixed pseudo-random direction per node."""
    counts = np.asarray(cells) + 1
    widths = np.asarray(lengths, dtype=float) / np.asarray(cells)
    k, j, i = np.meshgrid(*(np.arange(count) for count in counts[::-1]), indexing="ij")
    index = np.column_stack([i.ravel(), j.ravel(), k.ravel()])
    nodes = index * widths
    interior = np.all((index > 0) & (index < counts - 1), axis=1)
    angles = np.arange(len(nodes))[:, None] * np.array([0.7548776662, 0.5698402910, 0.3355])
    offsets = perturbation * widths * np.sin(2.0 * np.pi * angles)
    nodes[interior] += offsets[interior]
    return nodes, index


def _node_number(cells, i, j, k):
    return i + (cells[0] + 1) * (j + (cells[1] + 1) * k)


# The cube's corners as offsets (Gmsh's hexahedron order) and the six Kuhn tetrahedra around the
# diagonal 0-6: each path from corner (0,0,0) to (1,1,1) along the axes.
HEXAHEDRON_OFFSETS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1),
                      (1, 1, 1), (0, 1, 1)]
KUHN_PATHS = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
SIDE_NAMES = ("x0", "x1", "y0", "y1", "z0", "z1")


def _box_sides(cells, triangles):
    """name -> faces of the six sides x0, x1, y0, y1, z0, z1 (low, high side per axis): each
    square as a quadrilateral, or as two triangles split along the diagonal from its low to its
    high corner (the faces of the Kuhn tetrahedra)."""
    sides = {}
    for axis in range(3):
        first, second = [a for a in range(3) if a != axis]
        for side in (0, 1):
            faces = []
            for p in range(cells[first]):
                for q in range(cells[second]):
                    corners = []
                    for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        index = [0, 0, 0]
                        index[axis] = side * cells[axis]
                        index[first], index[second] = p + a, q + b
                        corners.append(_node_number(cells, *index))
                    if triangles:
                        faces += [[corners[0], corners[1], corners[2]],
                                  [corners[0], corners[3], corners[2]]]
                    else:
                        faces.append(corners)
            sides[SIDE_NAMES[2 * axis + side]] = np.array(faces, dtype=np.int64)
    return sides


def box_tetrahedra(cells, lengths, perturbation=0.0):
    """A box [0, L] of cells[0] x cells[1] x cells[2] cubes, each split into the six Kuhn
    tetrahedra (positively oriented), with its six sides as triangle boundaries. Returns
    (nodes, tetrahedra, sides)."""
    nodes, _ = _box_grid(cells, lengths, perturbation)
    tetrahedra = []
    for k in range(cells[2]):
        for j in range(cells[1]):
            for i in range(cells[0]):
                for path in KUHN_PATHS:
                    corner = np.array([i, j, k])
                    vertices = [corner.copy()]
                    for axis in path:
                        corner[axis] += 1
                        vertices.append(corner.copy())
                    tetrahedron = [_node_number(cells, *vertex) for vertex in vertices]
                    x = nodes[tetrahedron]
                    if np.cross(x[1] - x[0], x[2] - x[0]).dot(x[3] - x[0]) < 0.0:
                        tetrahedron[1], tetrahedron[2] = tetrahedron[2], tetrahedron[1]
                    tetrahedra.append(tetrahedron)
    return nodes, np.array(tetrahedra, dtype=np.int64), _box_sides(cells, True)


def box_hexahedra(cells, lengths, perturbation=0.0):
    """The same box as 8-node hexahedra (Gmsh's order) with quadrilateral sides."""
    nodes, _ = _box_grid(cells, lengths, perturbation)
    hexahedra = [[_node_number(cells, i + a, j + b, k + c) for a, b, c in HEXAHEDRON_OFFSETS]
                 for k in range(cells[2]) for j in range(cells[1]) for i in range(cells[0])]
    return nodes, np.array(hexahedra, dtype=np.int64), _box_sides(cells, False)


def solid_mesh_data(protocol, nodes, cell_type, cells, sides, source="box"):
    """MeshData (dimension 3) of one block of `cell_type` (protocol name) with tags 1, 2, ...
    and the sides as boundaries (TRIANGLE3 or QUADRILATERAL4 faces)."""
    message = protocol.MeshData(dimension=3, source=source)
    message.coordinates.extend(np.ravel(nodes).tolist())
    block = message.cells.add(type=protocol.CellType.Value(cell_type))
    block.connectivity.extend(int(node) for node in np.ravel(cells))
    block.tags.extend(range(1, len(cells) + 1))
    for name, faces in sorted(sides.items()):
        boundary = message.boundaries.add(name=name)
        boundary.segments.type = protocol.TRIANGLE3 if faces.shape[1] == 3 else \
            protocol.QUADRILATERAL4
        boundary.segments.connectivity.extend(int(node) for node in np.ravel(faces))
    return message


def solid_node_to_node_assignment(protocol, interface):
    """node_to_node_assignment of a solid body's InterfaceDescription (3 components)."""
    count = len(interface.node_ids)
    return protocol.AssignContact(
        row_offsets=range(0, 3 * count + 1, 3), node_ids=np.repeat(interface.node_ids, 3),
        components=[0, 1, 2] * count, values=interface.normals, weights=interface.weights)


def isotropic_solid_voigt(young, poisson):
    """The 6x6 Voigt stiffness (xx, yy, zz, yz, xz, xy) of an isotropic solid, written out here."""
    lame = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
    shear = young / (2.0 * (1.0 + poisson))
    matrix = np.diag([2.0 * shear] * 3 + [shear] * 3)
    matrix[:3, :3] += lame
    return matrix


def orthotropic_compliance(moduli, poissons, shears):
    """The 6x6 compliance S (strain = S stress, Voigt xx, yy, zz, yz, xz, xy) of an orthotropic
    solid: moduli (E1, E2, E3), poissons (nu12, nu13, nu23), shears (G23, G13, G12)."""
    e1, e2, e3 = moduli
    nu12, nu13, nu23 = poissons
    compliance = np.zeros((6, 6))
    compliance[:3, :3] = [[1.0 / e1, -nu12 / e1, -nu13 / e1],
                          [-nu12 / e1, 1.0 / e2, -nu23 / e2],
                          [-nu13 / e1, -nu23 / e2, 1.0 / e3]]
    compliance[3:, 3:] = np.diag(1.0 / np.asarray(shears, dtype=float))
    return compliance

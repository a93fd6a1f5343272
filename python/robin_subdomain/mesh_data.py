"""SetupBody.mesh (MeshData of proto/robin.proto, protocol 2.0) to a Mesh.

A mesh received on the wire is data only: nothing in it is opened, run or given to gmsh. Every
size is compared with the message's own array lengths before anything proportional to it is
allocated, and every index is checked before it is used. Each problem is an InputError (protocol
BAD_INPUT) naming the body, the SetupBody.mesh field and MeshData.source:
  - dimension is 2, or 3 (a solid body, protocol 2.4);
  - coordinates: d per node (a multiple of d, at least one node), all finite;
  - node_tags: empty (the nodes are then named 1, 2, ...) or one per node, each < 2^63;
  - cells: TRIANGLE3, TRIANGLE6 or QUADRILATERAL4 blocks (2D), TETRAHEDRON4 or HEXAHEDRON8
    blocks (3D), at least one cell in all; each block's connectivity a multiple of its nodes per
    cell, every index < the node count; tags empty or one per cell; every node is a node of a
    domain cell;
  - boundaries: names [A-Za-z0-9_.-]+ of at most 64 characters, unique; segments LINE2 or LINE3
    cells (2D), TRIANGLE3 or QUADRILATERAL4 faces (3D), at least one, checked like the domain's;
  - TETRAHEDRON10 cells and TRIANGLE6 faces of a solid mesh are valid protocol 2.4 but not
    implemented here: RequestError UNSUPPORTED naming the cell type and the field;
  - every domain cell has a strictly positive Jacobian at its nodes, its centroid and every
    quadrature point used on it (counter-clockwise or positively oriented, not folded, not
    degenerate); a bad cell is
    named by its tag, or by its 1-based position in its block when the block has no tags.
Cells are kept as sent: the sender orients them (no reordering, unlike the .msh reader).
"""

import re

import numpy as np

from . import fem
from .errors import InputError, RequestError
from .mesh import (HEXAHEDRON8, LINE2, LINE3, NODES_PER_ELEMENT, QUADRILATERAL4, TETRAHEDRON4,
                   TRIANGLE3, TRIANGLE6, BoundaryGroup, ElementBlock, Mesh)

# Per dimension: the domain cells and boundary facets (protocol name -> Mesh type) served, and
# those of the protocol this server does not implement (UNSUPPORTED, not BAD_INPUT).
DOMAIN_CELL_TYPES = {2: {"TRIANGLE3": TRIANGLE3, "TRIANGLE6": TRIANGLE6,
                         "QUADRILATERAL4": QUADRILATERAL4},
                     3: {"TETRAHEDRON4": TETRAHEDRON4, "HEXAHEDRON8": HEXAHEDRON8}}
SEGMENT_TYPES = {2: {"LINE2": LINE2, "LINE3": LINE3},
                 3: {"TRIANGLE3": TRIANGLE3, "QUADRILATERAL4": QUADRILATERAL4}}
UNSUPPORTED_CELL_TYPES = {2: (), 3: ("TETRAHEDRON10",)}
UNSUPPORTED_FACET_TYPES = {2: (), 3: ("TRIANGLE6",)}
BOUNDARY_NAME = re.compile(r"[A-Za-z0-9_.-]+")
MAXIMUM_NAME_LENGTH = 64
LARGEST_NODE_TAG = 2 ** 63 - 1


def quoted(text, limit=80):
    """A received string as messages show it: quoted, escaped, cut after `limit` characters."""
    shown = text if len(text) <= limit else text[:limit] + "..."
    return repr(shown)


class _Report:
    """Raises the InputError of a MeshData field, naming the body and the mesh's source."""

    def __init__(self, context, source):
        self.context = context
        self.source = quoted(source, 200) if source else "(MeshData.source not given)"

    def fail(self, field, problem):
        raise InputError("%s: SetupBody.mesh.%s %s (mesh %s)" %
                         (self.context, field, problem, self.source))


def _cell_type_name(protocol, value):
    try:
        return protocol.CellType.Name(value)
    except ValueError:
        return "unknown cell type %d" % value


def _nodes(message, report):
    """(coordinates (n x d), node tags (n)) of the MeshData."""
    dimension = message.dimension
    if dimension not in (2, 3):
        report.fail("dimension", "is %d, expected 2 (plane problems) or 3 (solid bodies)" %
                    dimension)
    count = len(message.coordinates)
    if count == 0 or count % dimension != 0:
        report.fail("coordinates", "has %d values, expected %d per node (%s), at least one node"
                    % (count, dimension, "x, y" if dimension == 2 else "x, y, z"))
    node_count = count // dimension
    coordinates = np.array(message.coordinates, dtype=float).reshape(node_count, dimension)
    bad = np.flatnonzero(~np.all(np.isfinite(coordinates), axis=1))
    if len(bad):
        report.fail("coordinates", "of node %d (1-based position) are not finite numbers" %
                    (bad[0] + 1))
    if len(message.node_tags) == 0:
        return coordinates, np.arange(1, node_count + 1, dtype=np.int64)
    if len(message.node_tags) != node_count:
        report.fail("node_tags", "has %d values for %d nodes, expected none or one per node" %
                    (len(message.node_tags), node_count))
    tags = np.array(message.node_tags, dtype=np.uint64)
    too_large = np.flatnonzero(tags > LARGEST_NODE_TAG)
    if len(too_large):
        report.fail("node_tags[%d]" % too_large[0], "is %d, larger than 2^63 - 1" %
                    int(tags[too_large[0]]))
    return coordinates, tags.astype(np.int64)


def _cell_block(block, field, node_count, allowed_types, protocol, report, unsupported=()):
    """(cell type, connectivity (cells x nodes per cell), tags or None) of a CellBlock whose
    type must be one of `allowed_types` (protocol name -> Mesh cell type); a type named in
    `unsupported` is a RequestError UNSUPPORTED."""
    type_name = _cell_type_name(protocol, block.type)
    if type_name in unsupported:
        raise RequestError("UNSUPPORTED", "%s: SetupBody.mesh.%s.type is %s, which this server "
                           "(robin-subdomain-py) does not implement: it solves %s; run the body "
                           "on robin-subdomain (mesh %s)" %
                           (report.context, field, type_name, " and ".join(allowed_types),
                            report.source))
    if type_name not in allowed_types:
        report.fail(field + ".type", "is %s, expected %s" % (type_name,
                                                             " or ".join(allowed_types)))
    cell_type = allowed_types[type_name]
    per_cell = NODES_PER_ELEMENT[cell_type]
    size = len(block.connectivity)
    if size % per_cell != 0:
        report.fail(field + ".connectivity", "has %d entries, not a multiple of the %d nodes of "
                    "a %s cell" % (size, per_cell, type_name))
    cell_count = size // per_cell
    if len(block.tags) not in (0, cell_count):
        report.fail(field + ".tags", "has %d values for %d cells, expected none or one per cell"
                    % (len(block.tags), cell_count))
    connectivity = np.array(block.connectivity, dtype=np.int64).reshape(cell_count, per_cell)
    outside = np.flatnonzero(connectivity.ravel() >= node_count)
    if len(outside):
        report.fail("%s.connectivity[%d]" % (field, outside[0]), "is %d, not an index of the %d "
                    "nodes (zero-based)" % (connectivity.ravel()[outside[0]], node_count))
    tags = np.array(block.tags, dtype=np.uint64) if len(block.tags) else None
    return cell_type, connectivity, tags


def _check_jacobians(nodes, block, field, report):
    """Every cell of `block` has a Jacobian > 0 at every check point (fem.jacobian_check_points).
    """
    coordinates = nodes[block.connectivity]
    points = fem.jacobian_check_points(block.type)
    determinants = np.column_stack([fem.jacobians(coordinates, block.type, point)[1]
                                    for point in points])
    bad_cells = np.flatnonzero(~np.all(determinants > 0.0, axis=1))
    if len(bad_cells) == 0:
        return
    cell = bad_cells[0]
    point = int(np.argmin(determinants[cell]))
    orientation = ("counter-clockwise" if len(points[point]) == 2 else
                   "positively oriented ((x1 - x0) x (x2 - x0) . (x3 - x0) > 0)")
    report.fail(field + ":", "cell %s (%s) is inverted, folded or degenerate: its Jacobian "
                "is %.6g at reference point %s; domain cells must be %s with a positive "
                "Jacobian everywhere; fix the mesh" %
                (block.element_label(cell), block.type, determinants[cell, point],
                 fem.format_reference(points[point]), orientation))


def _domain_blocks(message, nodes, protocol, report):
    """The ElementBlocks of MeshData.cells (empty blocks dropped), every node used and every
    Jacobian positive."""
    blocks = []
    used = np.zeros(len(nodes), dtype=bool)
    dimension = nodes.shape[1]
    for index, block in enumerate(message.cells):
        field = "cells[%d]" % index
        cell_type, connectivity, tags = _cell_block(block, field, len(nodes),
                                                    DOMAIN_CELL_TYPES[dimension], protocol,
                                                    report, UNSUPPORTED_CELL_TYPES[dimension])
        if len(connectivity) == 0:
            continue
        blocks.append((field, ElementBlock(cell_type, connectivity, tags)))
        used[connectivity.ravel()] = True
    if not blocks:
        report.fail("cells", "holds no domain cell: send the %s of the body" % (
            "triangles or quadrilaterals" if dimension == 2 else "tetrahedra or hexahedra"))
    unused = np.flatnonzero(~used)
    if len(unused):
        report.fail("coordinates", "define node %d (1-based position), which is not a node of "
                    "any domain cell" % (unused[0] + 1))
    for field, block in blocks:
        _check_jacobians(nodes, block, field, report)
    return [block for _, block in blocks]


def _boundaries(message, node_count, dimension, protocol, report):
    """name -> BoundaryGroup of MeshData.boundaries."""
    boundaries = {}
    for index, boundary in enumerate(message.boundaries):
        field = "boundaries[%d]" % index
        name = boundary.name
        if len(name) > MAXIMUM_NAME_LENGTH or not BOUNDARY_NAME.fullmatch(name):
            report.fail(field + ".name", "%s is not a boundary name ([A-Za-z0-9_.-], 1 to %d "
                        "characters)" % (quoted(name), MAXIMUM_NAME_LENGTH))
        if name in boundaries:
            report.fail(field + ".name", "'%s' names two boundaries: names are unique" % name)
        segment_type, connectivity, _ = _cell_block(
            boundary.segments, field + ".segments", node_count, SEGMENT_TYPES[dimension],
            protocol, report, UNSUPPORTED_FACET_TYPES[dimension])
        if len(connectivity) == 0:
            report.fail(field + ".segments", "of boundary '%s' holds no segment" % name)
        boundaries[name] = BoundaryGroup(segment_type, connectivity)
    return boundaries


def decode_mesh_data(message, protocol, context):
    """The Mesh of a MeshData message (see the module comment); `protocol` is the robin_pb2
    module, `context` names the body in messages ("body 'lower'")."""
    report = _Report(context, message.source)
    nodes, node_tags = _nodes(message, report)
    blocks = _domain_blocks(message, nodes, protocol, report)
    boundaries = _boundaries(message, len(nodes), nodes.shape[1], protocol, report)
    return Mesh(nodes, node_tags, blocks, boundaries)

"""A body's result fields under contact forces lambda (FieldsReply of proto/robin.proto), and
the bytes of their VTK XML unstructured-grid file (binary zlib-compressed .vtu, with the named
boundaries as line cells; paths.write_under_root writes it).

Point fields, d = 2 (plane) or 3 (solid) components per vector: displacement (d), stress (6:
XX, YY, ZZ, XY, YZ, XZ; nodal average; plane: ZZ = out_of_plane_poisson (XX + YY),
YZ = XZ = 0), von_mises, contact_pressure (|(B' lambda) at the node| / m_i, m_i the node's
weight on the contact boundaries; 0 off them), contact_force (d: -B' lambda at each node),
reaction (d: K u - f at prescribed dofs). Cell fields: stress (6, element centroids),
von_mises. A solid body's .vtu has its tetrahedra and hexahedra and its boundary faces.
reaction_resultant: sum of the reactions; applied_force: sum of body forces and tractions.
"""

import struct
import zlib
from xml.sax.saxutils import escape

import numpy as np

from . import fem
from .material import stress_tensors
from .mesh import CORNER_COUNT, LINE2, LINE3, QUADRILATERAL4, TRIANGLE3, VTK_CELL_TYPE


class BodyFields:
    def __init__(self, point_fields, cell_fields, reaction_resultant, applied_force):
        self.point_fields = point_fields   # [(name, components, values (n x components))]
        self.cell_fields = cell_fields
        self.reaction_resultant = reaction_resultant
        self.applied_force = applied_force


def body_fields(body, contact_force):
    """The fields of `body` (with an assigned contact) under contact forces lambda (one per
    constraint)."""
    mesh = body.mesh
    dimension = mesh.dimension
    displacement = body.displacement(contact_force)
    element_stress, nodal_stress, element_von_mises, nodal_von_mises = fem.recover_stress(
        mesh, body.definition.material, displacement)
    reaction = body.reactions(displacement)
    force_field = -body.contact.nodal_forces(contact_force).reshape(-1, dimension)
    weights = body.interface.node_weights
    pressure = np.zeros(mesh.node_count())
    positive = weights > 0.0
    pressure[positive] = np.linalg.norm(force_field[positive], axis=1) / weights[positive]
    material = body.definition.material
    point_fields = [("displacement", dimension, displacement.reshape(-1, dimension)),
                    ("stress", 6, stress_tensors(material, nodal_stress)),
                    ("von_mises", 1, nodal_von_mises[:, None]),
                    ("contact_pressure", 1, pressure[:, None]),
                    ("contact_force", dimension, force_field),
                    ("reaction", dimension, reaction.reshape(-1, dimension))]
    cell_fields = [("stress", 6, stress_tensors(material, element_stress)),
                   ("von_mises", 1, element_von_mises[:, None])]
    return BodyFields(point_fields, cell_fields, reaction.reshape(-1, dimension).sum(axis=0),
                      body.applied_force())


VTU_BLOCK_SIZE = 32768  # uncompressed bytes per zlib block (vtkZLibDataCompressor's default)
# VTK_LINE, VTK_QUADRATIC_EDGE (endpoints, then midpoint); boundary faces of solid meshes.
VTK_EDGE_TYPE = {LINE2: 3, LINE3: 21, TRIANGLE3: 5, QUADRILATERAL4: 9}
STRESS_COMPONENTS = ("XX", "YY", "ZZ", "XY", "YZ", "XZ")


def _compressed_record(raw):
    """`raw` in vtkZLibDataCompressor's layout: UInt64 words [blocks, block size, size of the
    last block (0 when full), compressed size of each block], then the zlib streams."""
    blocks = [zlib.compress(raw[begin:begin + VTU_BLOCK_SIZE], 1)  # fastest, as the C++ writer
              for begin in range(0, len(raw), VTU_BLOCK_SIZE)]
    header = struct.pack("<%dQ" % (3 + len(blocks)), len(blocks), VTU_BLOCK_SIZE,
                         len(raw) % VTU_BLOCK_SIZE, *(len(block) for block in blocks))
    return header + b"".join(blocks)


def _adjacent_cells(mesh, boundary_names):
    """For every face of the boundaries of a solid mesh (in the given order), the index of the
    first volume element holding all its corners, -1 when none does."""
    firsts = np.cumsum([0] + [len(block.connectivity) for block in mesh.blocks])
    groups = [mesh.boundaries[name].connectivity for name in boundary_names]
    nodes = np.unique(np.concatenate([group.ravel() for group in groups] + [[0]]))
    owners = fem.node_elements(mesh, nodes)
    adjacent = []
    for group in groups:
        for corners in group:
            found = fem.element_with(mesh, owners, corners)
            adjacent.append(-1 if found is None else firsts[found[0]] + found[1])
    return np.array(adjacent, dtype=np.int64)


def _adjacent_elements(mesh, boundary_names):
    """For every edge of the boundaries (in the given order), the index of an area element that
    has it as a side (its two endpoints are corners of the element), -1 when none has; in 3D
    the face's volume element (_adjacent_cells)."""
    if mesh.dimension == 3:
        return _adjacent_cells(mesh, boundary_names)
    side_of = {}
    first = 0
    for block in mesh.blocks:
        corners = CORNER_COUNT[block.type]
        for a in range(corners):
            ends = np.sort(block.connectivity[:, [a, (a + 1) % corners]], axis=1)
            for element, (low, high) in enumerate(ends.tolist()):
                side_of.setdefault((low, high), first + element)
        first += len(block.connectivity)
    adjacent = []
    for name in boundary_names:
        for edge in mesh.boundaries[name].connectivity[:, :2].tolist():
            adjacent.append(side_of.get((min(edge), max(edge)), -1))
    return np.array(adjacent, dtype=np.int64)


def vtu_bytes(mesh, fields):
    """The .vtu file (VTK XML unstructured grid) of `mesh` and its BodyFields, as the C++
    writer writes it (subdomain/numerics/vtu_writer.hpp): appended raw binary arrays compressed
    by zlib (vtkZLibDataCompressor, header_type UInt64); cells: the area elements, then the
    edges of every named boundary (name order) as VTK_LINE / VTK_QUADRATIC_EDGE; the cell field
    boundary_id (0 on area elements, k on the edges of the k-th boundary) and the field-data
    string array boundary_names; on an edge, each cell field holds the values of the area
    element that has it as a side (NaN when none has). 2-component fields get a zero third."""
    names = sorted(mesh.boundaries)
    element_count = mesh.element_count()
    adjacent = _adjacent_elements(mesh, names)
    cells = [block.connectivity for block in mesh.blocks]
    cells += [mesh.boundaries[name].connectivity for name in names]
    connectivity = np.concatenate([c.ravel() for c in cells]).astype("<i8")
    offsets = np.cumsum(np.concatenate([np.full(len(c), c.shape[1]) for c in cells])).astype("<i8")
    types = np.concatenate([np.full(len(block.connectivity), VTK_CELL_TYPE[block.type])
                            for block in mesh.blocks] +
                           [np.full(len(mesh.boundaries[name].connectivity),
                                    VTK_EDGE_TYPE[mesh.boundaries[name].type]) for name in names])
    boundary_id = np.concatenate([np.zeros(element_count)] +
                                 [np.full(len(mesh.boundaries[name].connectivity), k + 1)
                                  for k, name in enumerate(names)])
    appended = []
    offset = [0]

    def data_array(kind, name, values, components=1, component_names=(), strings=None):
        if strings is not None:
            raw = b"".join(text.encode() + b"\0" for text in strings)
            size = 'NumberOfTuples="%d"' % len(strings)
        else:
            raw = np.ascontiguousarray(values).astype(
                {"Float64": "<f8", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1"}[kind]).tobytes()
            size = 'NumberOfComponents="%d"' % components
        record = _compressed_record(raw)
        labels = "".join(' ComponentName%d="%s"' % (c, label)
                         for c, label in enumerate(component_names))
        element = ('        <DataArray type="%s" Name="%s" %s%s format="appended" offset="%d"/>\n'
                   % (kind, escape(name, {'"': "&quot;"}), size, labels, offset[0]))
        appended.append(record)
        offset[0] += len(record)
        return element

    def field_array(name, components, values, extra):
        values = np.asarray(values, dtype=np.float64).reshape(-1, components)
        if extra is not None:
            padding = np.full((len(extra), components), np.nan)
            padding[extra >= 0] = values[extra[extra >= 0]]
            values = np.vstack([values, padding])
        if components == 2 and mesh.dimension == 2:
            values = np.column_stack([values, np.zeros(len(values))])
        labels = STRESS_COMPONENTS if name == "stress" and components == 6 else ()
        return data_array("Float64", name, values, values.shape[1], labels)

    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
             'header_type="UInt64" compressor="vtkZLibDataCompressor">\n',
             '  <UnstructuredGrid>\n']
    if names:
        parts += ['    <FieldData>\n', data_array("String", "boundary_names", None, strings=names),
                  '    </FieldData>\n']
    parts.append('    <Piece NumberOfPoints="%d" NumberOfCells="%d">\n      <PointData>\n'
                 % (mesh.node_count(), len(types)))
    parts += [field_array(name, components, values, None)
              for name, components, values in fields.point_fields]
    parts.append('      </PointData>\n      <CellData>\n')
    parts += [field_array(name, components, values, adjacent)
              for name, components, values in fields.cell_fields]
    parts.append(data_array("Int32", "boundary_id", boundary_id))
    parts.append('      </CellData>\n      <Points>\n')
    points = mesh.nodes
    if mesh.dimension == 2:
        points = np.column_stack([mesh.nodes, np.zeros(mesh.node_count())])
    parts.append(data_array("Float64", "Points", points, 3))
    parts.append('      </Points>\n      <Cells>\n')
    parts += [data_array("Int64", "connectivity", connectivity),
              data_array("Int64", "offsets", offsets), data_array("UInt8", "types", types)]
    parts.append('      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n'
                 '  <AppendedData encoding="raw">\n   _')
    return ("".join(parts).encode() + b"".join(appended) +
            b"\n  </AppendedData>\n</VTKFile>\n")

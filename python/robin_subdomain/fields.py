"""A body's result fields under contact forces lambda (FieldsReply of proto/robin.proto), and
the text of their VTK XML unstructured-grid file (ASCII .vtu; paths.write_under_root writes it).

Point fields: displacement (2), stress (3: xx, yy, xy; nodal average), von_mises,
contact_pressure (|(B' lambda) at the node| / m_i, m_i the node's weight on the contact
boundaries; 0 off them), contact_force (2: -B' lambda at each node), reaction (2: K u - f at
prescribed dofs). Cell fields: stress (3, element centroids), von_mises.
reaction_resultant: sum of the reactions; applied_force: sum of body forces and tractions.
"""

import numpy as np

from . import fem
from .mesh import NODES_PER_ELEMENT, VTK_CELL_TYPE


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
    displacement = body.displacement(contact_force)
    element_stress, nodal_stress, element_von_mises, nodal_von_mises = fem.recover_stress(
        mesh, body.definition.material, displacement)
    reaction = body.reactions(displacement)
    force_field = -body.contact.nodal_forces(contact_force).reshape(-1, 2)
    weights = body.interface.node_weights
    pressure = np.zeros(mesh.node_count())
    positive = weights > 0.0
    pressure[positive] = np.hypot(force_field[positive, 0],
                                  force_field[positive, 1]) / weights[positive]
    point_fields = [("displacement", 2, displacement.reshape(-1, 2)),
                    ("stress", 3, nodal_stress), ("von_mises", 1, nodal_von_mises[:, None]),
                    ("contact_pressure", 1, pressure[:, None]),
                    ("contact_force", 2, force_field), ("reaction", 2, reaction.reshape(-1, 2))]
    cell_fields = [("stress", 3, element_stress), ("von_mises", 1, element_von_mises[:, None])]
    return BodyFields(point_fields, cell_fields, reaction.reshape(-1, 2).sum(axis=0),
                      body.applied_force())


def _data_array(name, components, values, indent):
    text = " ".join(repr(float(value)) for value in np.ravel(values))
    return ('%s<DataArray type="Float64" Name="%s" NumberOfComponents="%d" format="ascii">%s'
            '</DataArray>\n' % (indent, name, components, text))


def vtu_text(mesh, fields):
    """The .vtu file (VTK XML unstructured grid, ASCII) of `mesh` and its BodyFields."""
    connectivity = np.concatenate([block.connectivity.ravel() for block in mesh.blocks])
    sizes = np.concatenate([np.full(len(block.connectivity), NODES_PER_ELEMENT[block.type])
                            for block in mesh.blocks])
    types = np.concatenate([np.full(len(block.connectivity), VTK_CELL_TYPE[block.type])
                            for block in mesh.blocks])
    points = np.column_stack([mesh.nodes, np.zeros(mesh.node_count())])
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">\n',
             '<UnstructuredGrid>\n<Piece NumberOfPoints="%d" NumberOfCells="%d">\n' %
             (mesh.node_count(), mesh.element_count()),
             '<Points>\n', _data_array("Points", 3, points, "  "), '</Points>\n', '<Cells>\n',
             '  <DataArray type="Int64" Name="connectivity" format="ascii">%s</DataArray>\n' %
             " ".join(map(str, connectivity)),
             '  <DataArray type="Int64" Name="offsets" format="ascii">%s</DataArray>\n' %
             " ".join(map(str, np.cumsum(sizes))),
             '  <DataArray type="UInt8" Name="types" format="ascii">%s</DataArray>\n' %
             " ".join(map(str, types)), '</Cells>\n', '<PointData>\n']
    parts += [_data_array(field, components, values, "  ")
              for field, components, values in fields.point_fields]
    parts += ['</PointData>\n', '<CellData>\n']
    parts += [_data_array(field, components, values, "  ")
              for field, components, values in fields.cell_fields]
    parts += ['</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n']
    return "".join(parts)

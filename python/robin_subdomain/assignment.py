"""The contact constraint operator B of a body (AssignContact of proto/robin.proto, protocol 2.0).

B has one row per constraint j, in compressed rows over (node, component) pairs:
    (B u)_j = sum over k in [row_offsets[j], row_offsets[j+1]) of values[k] u_c(node_ids[k]),
with c = components[k], and a weight m_j > 0 per row (pressure_j = lambda_j / m_j). Node-to-node
contact is the special case of one row per contact node with the components of its unit normal
(ContactOperator.node_to_node).

decode_assign_contact checks a request before anything is built from it: sizes first (each
compared with the message's own array lengths), then values; every problem is a RequestError
INVALID_ARGUMENT naming the body and the AssignContact field.
"""

import numpy as np

from .errors import RequestError


class ContactOperator:
    """B as entries: entry_rows, node_ids, components, values (entries), weights (rows), on a
    body of `dimension` components per node."""

    def __init__(self, row_offsets, node_ids, components, values, weights, dimension=2):
        self.dimension = dimension
        offsets = np.asarray(row_offsets, dtype=np.int64)
        self.row_count = len(offsets) - 1
        self.entry_rows = np.repeat(np.arange(self.row_count), np.diff(offsets))
        self.node_ids = np.asarray(node_ids, dtype=np.int64)
        self.components = np.asarray(components, dtype=np.int64)
        self.values = np.asarray(values, dtype=float)
        self.weights = np.asarray(weights, dtype=float)

    def dofs(self):
        """The global degree of freedom of every entry (node i has component c at d i + c)."""
        return self.dimension * self.node_ids + self.components

    @classmethod
    def node_to_node(cls, node_ids, normals, weights):
        """One row per node: (B u)_i = u(node_i) . n_i, with normals (nodes x d)."""
        count, dimension = np.shape(normals)
        return cls(np.arange(0, dimension * count + 1, dimension),
                   np.repeat(node_ids, dimension), np.tile(np.arange(dimension), count),
                   np.ravel(normals), weights, dimension)


def _invalid(body_name, field, problem):
    return RequestError("INVALID_ARGUMENT", "AssignContact for body '%s': AssignContact.%s %s" %
                        (body_name, field, problem))


def _check_sizes(message, body_name):
    """The number of rows, once row_offsets, node_ids, components, values and weights agree."""
    offsets, entries = message.row_offsets, len(message.values)
    if len(offsets) == 0 or offsets[0] != 0:
        raise _invalid(body_name, "row_offsets", "must start with 0 (constraints + 1 entries: 0, "
                       "..., the number of entries)")
    if offsets[-1] != entries:
        raise _invalid(body_name, "row_offsets", "ends with %d, expected the number of entries "
                       "(%d values)" % (offsets[-1], entries))
    for field in ("node_ids", "components"):
        if len(getattr(message, field)) != entries:
            raise _invalid(body_name, field, "has %d values for %d entries (values)" %
                           (len(getattr(message, field)), entries))
    rows = len(offsets) - 1
    if rows < 1:
        raise _invalid(body_name, "row_offsets", "describes no constraint (at least one is needed)")
    if len(message.weights) != rows:
        raise _invalid(body_name, "weights", "has %d values for %d constraints (row_offsets)" %
                       (len(message.weights), rows))
    return rows


def _check_offsets(message, body_name):
    offsets = np.array(message.row_offsets, dtype=np.uint64)
    bad = np.flatnonzero(offsets[1:] <= offsets[:-1])
    if len(bad):
        row = bad[0]
        problem = "is empty" if offsets[row + 1] == offsets[row] else "ends before it starts"
        raise _invalid(body_name, "row_offsets", "[%d..%d]: row %d %s (every row has at least "
                       "one entry, offsets increase)" % (row, row + 1, row, problem))
    return offsets.astype(np.int64)


def _check_numbers(message, body_name, dimension):
    for field, values in (("values", message.values), ("weights", message.weights)):
        array = np.array(values, dtype=float)
        bad = np.flatnonzero(~np.isfinite(array))
        if len(bad):
            raise _invalid(body_name, "%s[%d]" % (field, bad[0]), "is not a finite number")
    weights = np.array(message.weights, dtype=float)
    bad = np.flatnonzero(~(weights > 0.0))
    if len(bad):
        raise _invalid(body_name, "weights[%d]" % bad[0], "is %.6g, expected > 0" %
                       weights[bad[0]])
    components = np.array(message.components, dtype=np.int64)
    bad = np.flatnonzero(components >= dimension)
    if len(bad):
        expected = "0 (x) or 1 (y)" if dimension == 2 else "0 (x), 1 (y) or 2 (z)"
        raise _invalid(body_name, "components[%d]" % bad[0], "is %d, expected %s" %
                       (components[bad[0]], expected))


def _check_nodes(message, contact_node_ids, body_name):
    """Every node id is a contact node (contact_node_ids ascending)."""
    node_ids = np.array(message.node_ids, dtype=np.int64)
    if len(contact_node_ids) == 0:
        found = np.zeros(len(node_ids), dtype=bool)
    else:
        positions = np.minimum(np.searchsorted(contact_node_ids, node_ids),
                               len(contact_node_ids) - 1)
        found = contact_node_ids[positions] == node_ids
    bad = np.flatnonzero(~found)
    if len(bad):
        raise _invalid(body_name, "node_ids[%d]" % bad[0], "is %d, not a node of the contact "
                       "boundaries (see InterfaceDescription.node_ids)" % node_ids[bad[0]])


def _check_distinct(operator, node_tags, body_name):
    """The entries of a row name distinct (node, component) pairs."""
    dofs = operator.dofs()
    order = np.lexsort((dofs, operator.entry_rows))
    same = ((operator.entry_rows[order][1:] == operator.entry_rows[order][:-1]) &
            (dofs[order][1:] == dofs[order][:-1]))
    repeated = np.flatnonzero(same)
    if len(repeated):
        entry = order[repeated[0] + 1]
        node = operator.node_ids[entry]
        raise _invalid(body_name, "node_ids[%d]" % entry, "repeats node id %d (tag %d), "
                       "component %d, in row %d: the entries of a row name distinct (node, "
                       "component) pairs" % (node, node_tags[node], operator.components[entry],
                                             operator.entry_rows[entry]))


def decode_assign_contact(message, contact_node_ids, node_tags, body_name, dimension=2):
    """The ContactOperator of an AssignContact whose node ids must be among contact_node_ids
    (ascending; node_tags names the mesh's nodes in messages) on a body of `dimension`.
    RequestError INVALID_ARGUMENT for any inconsistent size or value (see the module
    comment)."""
    _check_sizes(message, body_name)
    offsets = _check_offsets(message, body_name)
    _check_numbers(message, body_name, dimension)
    _check_nodes(message, contact_node_ids, body_name)
    operator = ContactOperator(offsets, message.node_ids, message.components, message.values,
                               message.weights, dimension)
    _check_distinct(operator, node_tags, body_name)
    return operator

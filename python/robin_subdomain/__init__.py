"""robin_subdomain: a reference external subdomain server of robin-contact, in Python.

A second, independent implementation of one elastic body of the Robin domain decomposition
(proto/robin.proto, protocol 2.5, docs/protocol.md): meshes received as data (MeshData) or read
from the operator's data directory by its own Gmsh reader (plane meshes only), finite elements
(P1, P2 triangles and Q1 quadrilaterals, plane strain or stress; since 2.4 solid bodies of P1
tetrahedra and Q1 hexahedra received as MeshData, with TRIANGLE3 and QUADRILATERAL4 boundary
faces; TETRAHEDRON10 cells and TRIANGLE6 faces are refused with UNSUPPORTED), sparse LU
factorization (SuperLU via SciPy), a
general sparse contact constraint operator B, dense interface compliance and bound-constrained
contact QP; since 2.5 the peak resident set size in the replies of the long requests and
FieldsReply without mesh and fields for a file it wrote (omit_fields_from_reply). Nothing here
calls the C++ code.
"""

VERSION = "0.1.0"
SERVER_NAME = "robin-subdomain-py " + VERSION

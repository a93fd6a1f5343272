"""SetupBody (proto/robin.proto, protocol 2.0) to a BodyDefinition and the solver settings, with
the checks and messages of the C++ server (subdomain/server/setup_decoding.cpp). Every problem is
an InputError (BAD_INPUT) naming the body and the SetupBody field.

The mesh is SetupBody.mesh (MeshData, decoded by mesh_data.py: data only, never given to gmsh),
or else SetupBody.mesh_path: a .msh or .geo file of the server's operator under the data
directory given at start (--data-directory; paths.resolve_data_file), read by mesh.read_mesh.
Without a data directory every mesh_path is refused.

Solid bodies (protocol 2.4): a SetupBody whose MeshData has dimension 3 has a solid material
(36 Voigt values, or E and nu of the isotropic solid; `model` is ignored), 3-component body
force and traction vectors, and Dirichlet conditions that may prescribe z. A mesh file
(mesh_path) is always read as a plane mesh.
"""

import math
import re

from . import mesh as mesh_reader
from .body import BodyDefinition
from .errors import InputError
from .mesh_data import decode_mesh_data, quoted
from .paths import PathRefused, resolve_data_file
from .material import PLANE_STRAIN, PLANE_STRESS, SOLID, isotropic_material, voigt_material

DEFAULT_QP_TOLERANCE = 1e-12
DEFAULT_QP_MAX_ITERATIONS = 20000
MAXIMUM_BODY_NAME_LENGTH = 64
LISTED_BOUNDARY_NAMES = 20


class SolverSettings:
    def __init__(self):
        self.qp_tolerance = DEFAULT_QP_TOLERANCE
        self.qp_max_iterations = DEFAULT_QP_MAX_ITERATIONS


def _fail(context, field, problem):
    raise InputError("%s: SetupBody.%s %s" % (context, field, problem))


def _number(value):
    return "%.12g" % value


def _body_name(name):
    if len(name) > MAXIMUM_BODY_NAME_LENGTH or not re.fullmatch(r"[A-Za-z0-9_-]+", name):
        raise InputError("SetupBody.body_name %s is not a valid body name (letters, digits, '_' "
                         "and '-', 1 to %d characters)" % (quoted(name),
                                                           MAXIMUM_BODY_NAME_LENGTH))
    return name


def _dimension(message):
    """3 for a solid body (SetupBody.mesh of dimension 3), else 2: the dimension the material,
    loads and Dirichlet conditions are read in (the mesh decoding checks the dimension itself).
    """
    return 3 if message.HasField("mesh") and message.mesh.dimension == 3 else 2


def _model(message, protocol, context, dimension):
    if dimension == 3:
        return SOLID
    if message.model == protocol.PLANE_STRAIN:
        return PLANE_STRAIN
    if message.model == protocol.PLANE_STRESS:
        return PLANE_STRESS
    _fail(context, "model", "is unspecified: give PLANE_STRAIN or PLANE_STRESS")


def _material(message, protocol, context, dimension):
    model = _model(message, protocol, context, dimension)
    material_context = context + ": SetupBody material"
    if len(message.voigt) == 0:
        return isotropic_material(message.young_modulus, message.poisson_ratio, model,
                                  material_context)
    if message.young_modulus != 0.0 or message.poisson_ratio != 0.0:
        _fail(context, "voigt", "is given together with young_modulus/poisson_ratio: give one of "
              "them")
    if dimension == 3 and len(message.voigt) != 36:
        _fail(context, "voigt", "has %d values, expected 36 (row-major 6x6, order xx, yy, zz, "
              "yz, xz, xy) for a solid body" % len(message.voigt))
    if dimension == 2 and len(message.voigt) != 9:
        _fail(context, "voigt", "has %d values, expected 9 (row-major 3x3)" % len(message.voigt))
    return voigt_material(list(message.voigt), model, material_context)


def _vector(values, context, field, dimension=2):
    if len(values) != dimension:
        _fail(context, field, "has %d values, expected %s" % (
            len(values), "2 (x, y)" if dimension == 2 else "3 (x, y, z)"))
    if not all(math.isfinite(value) for value in values):
        _fail(context, field, "has a value that is not a finite number")
    return tuple(float(value) for value in values)


def _solver(message, context):
    settings = SolverSettings()
    tolerance = message.qp_tolerance
    if not math.isfinite(tolerance) or tolerance < 0.0:
        _fail(context, "solver.qp_tolerance",
              "is %s, expected > 0 (or 0 for the default)" % _number(tolerance))
    if tolerance > 0.0:
        settings.qp_tolerance = tolerance
    if message.qp_max_iterations > 0:
        if message.qp_max_iterations > 2 ** 31 - 1:
            _fail(context, "solver.qp_max_iterations", "is too large")
        settings.qp_max_iterations = message.qp_max_iterations
    if message.interface_operator not in ("", "auto", "dense", "factor"):
        _fail(context, "solver.interface_operator",
              "is '%s', expected \"auto\", \"dense\" or \"factor\"" % message.interface_operator)
    if message.dense_limit > 2 ** 31 - 1:
        _fail(context, "solver.dense_limit", "is too large")
    if message.linear_solver not in ("", "direct", "multigrid"):
        _fail(context, "solver.linear_solver",
              "is '%s', expected \"direct\" or \"multigrid\"" % message.linear_solver)
    # interface_operator, dense_limit and linear_solver are hints; this server always assembles
    # F densely and solves K x = b directly.
    return settings


def _mesh_file(message, data_directory, context):
    """The mesh of SetupBody.mesh_path, a file under the data directory (or None)."""
    try:
        path = resolve_data_file(data_directory, message.mesh_path)
    except PathRefused as refusal:
        _fail(context, "mesh_path", "%s %s" % (quoted(message.mesh_path), refusal))
    return mesh_reader.read_mesh(path, "%s: SetupBody.mesh_path: mesh file %s" %
                                 (context, quoted(message.mesh_path)))


def _mesh(message, protocol, data_directory, context):
    """The body's mesh: SetupBody.mesh when given, else the file SetupBody.mesh_path."""
    if message.HasField("mesh"):
        return decode_mesh_data(message.mesh, protocol, context)
    if not message.mesh_path:
        _fail(context, "mesh", "and SetupBody.mesh_path are both empty: send the mesh")
    return _mesh_file(message, data_directory, context)


def _check_boundary(mesh, name, context, field):
    if not name:
        _fail(context, field, "is empty: give the name of a boundary of the mesh")
    if name not in mesh.boundaries:
        names = sorted(mesh.boundaries)
        known = ", ".join(names[:LISTED_BOUNDARY_NAMES]) or "none"
        if len(names) > LISTED_BOUNDARY_NAMES:
            known += ", ... (%d in all)" % len(names)
        _fail(context, field, "%s is not a boundary of the mesh (its boundaries: %s)" %
              (quoted(name), known))


# The most contact boundaries a body may name (robin-subdomain's limit, setup_decoding.hpp).
MAXIMUM_CONTACT_BOUNDARIES = 64


def _contact_boundaries(message, mesh, context):
    """SetupBody.contact_boundaries: 1 to MAXIMUM_CONTACT_BOUNDARIES distinct named boundaries."""
    count = len(message.contact_boundaries)
    if count == 0:
        _fail(context, "contact_boundaries", "is empty: name at least one boundary that may "
              "touch another body")
    if count > MAXIMUM_CONTACT_BOUNDARIES:
        _fail(context, "contact_boundaries", "has %d names, more than the %d contact boundaries "
              "a body may have" % (count, MAXIMUM_CONTACT_BOUNDARIES))
    names = list(message.contact_boundaries)
    for index, name in enumerate(names):
        _check_boundary(mesh, name, context, "contact_boundaries[%d]" % index)
        if name in names[:index]:
            _fail(context, "contact_boundaries[%d]" % index, "repeats '%s'" % name)
    return names


def _dirichlet(message, mesh, context, field):
    """(boundary, x, y) or, for a solid body, (boundary, x, y, z); None where not given."""
    _check_boundary(mesh, message.boundary, context, field + ".boundary")
    if message.HasField("z") and mesh.dimension == 2:
        _fail(context, field + ".z", "is given, but the body is two-dimensional: give x and y "
              "only")
    names = ("x", "y", "z")[:mesh.dimension]
    values = [getattr(message, name) if message.HasField(name) else None for name in names]
    if all(value is None for value in values):
        _fail(context, field, "prescribes neither x nor y: give at least one" if mesh.dimension
              == 2 else "prescribes none of x, y and z: give at least one")
    if any(value is not None and not math.isfinite(value) for value in values):
        _fail(context, field, "has a value that is not a finite number")
    return (message.boundary, *values)


def _traction(message, mesh, context, field):
    _check_boundary(mesh, message.boundary, context, field + ".boundary")
    if not message.is_pressure:
        return (message.boundary, _vector(message.vector, context, field + ".vector",
                                          mesh.dimension), None)
    if len(message.vector) != 0:
        _fail(context, field + ".vector", "is given with is_pressure = true: give one of them")
    if not math.isfinite(message.pressure):
        _fail(context, field + ".pressure", "is not a finite number")
    return (message.boundary, None, message.pressure)


def decode_setup_body(message, protocol, data_directory=None):
    """(BodyDefinition, SolverSettings) of a SetupBody; `protocol` is the robin_pb2 module,
    `data_directory` the directory mesh_path is resolved in (None: mesh_path refused)."""
    name = _body_name(message.body_name)
    context = "body '%s'" % name
    dimension = _dimension(message)
    material = _material(message, protocol, context, dimension)
    body_force = (0.0,) * dimension
    if len(message.body_force):
        body_force = _vector(message.body_force, context, "body_force", dimension)
    settings = _solver(message.solver, context)
    mesh = _mesh(message, protocol, data_directory, context)
    contact_boundaries = _contact_boundaries(message, mesh, context)
    dirichlet = [_dirichlet(condition, mesh, context, "dirichlet[%d]" % k)
                 for k, condition in enumerate(message.dirichlet)]
    tractions = [_traction(condition, mesh, context, "traction[%d]" % k)
                 for k, condition in enumerate(message.traction)]
    definition = BodyDefinition(name, mesh, material, body_force, dirichlet, tractions,
                                contact_boundaries)
    return definition, settings

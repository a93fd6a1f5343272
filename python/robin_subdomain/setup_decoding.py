"""SetupBody (proto/robin.proto) to a BodyDefinition and the solver settings, with the checks
and messages of the C++ server (subdomain/server/setup_decoding.cpp). Every problem is an
InputError naming the body and the SetupBody field.
"""

import math
import pathlib
import re

from . import mesh as mesh_reader
from .body import BodyDefinition
from .errors import InputError
from .material import PLANE_STRAIN, PLANE_STRESS, isotropic_material, voigt_material

DEFAULT_QP_TOLERANCE = 1e-12
DEFAULT_QP_MAX_ITERATIONS = 20000


class SolverSettings:
    def __init__(self):
        self.qp_tolerance = DEFAULT_QP_TOLERANCE
        self.qp_max_iterations = DEFAULT_QP_MAX_ITERATIONS


def _fail(context, field, problem):
    raise InputError("%s: SetupBody.%s %s" % (context, field, problem))


def _number(value):
    return "%.12g" % value


def _body_name(name):
    if not re.fullmatch(r"[A-Za-z0-9_-]+", name):
        raise InputError("SetupBody.body_name '%s' is not a valid body name (letters, digits, '_' "
                         "and '-', not empty)" % name)
    return name


def _model(message, protocol, context):
    if message.model == protocol.PLANE_STRAIN:
        return PLANE_STRAIN
    if message.model == protocol.PLANE_STRESS:
        return PLANE_STRESS
    _fail(context, "model", "is unspecified: give PLANE_STRAIN or PLANE_STRESS")


def _material(message, protocol, context):
    model = _model(message, protocol, context)
    material_context = context + ": SetupBody material"
    if len(message.voigt) == 0:
        return isotropic_material(message.young_modulus, message.poisson_ratio, model,
                                  material_context)
    if message.young_modulus != 0.0 or message.poisson_ratio != 0.0:
        _fail(context, "voigt", "is given together with young_modulus/poisson_ratio: give one of "
              "them")
    if len(message.voigt) != 9:
        _fail(context, "voigt", "has %d values, expected 9 (row-major 3x3)" % len(message.voigt))
    return voigt_material(list(message.voigt), model, material_context)


def _vector(values, context, field):
    if len(values) != 2:
        _fail(context, field, "has %d values, expected 2 (x, y)" % len(values))
    if not (math.isfinite(values[0]) and math.isfinite(values[1])):
        _fail(context, field, "has a value that is not a finite number")
    return (float(values[0]), float(values[1]))


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
    # interface_operator and dense_limit are hints; this server always assembles F densely.
    return settings


def _mesh_options(message, context):
    if not math.isfinite(message.mesh_size) or message.mesh_size < 0.0:
        _fail(context, "mesh_size", "is %s, expected >= 0" % _number(message.mesh_size))
    if message.element_order > 2:
        _fail(context, "element_order",
              "is %d, expected 1 or 2 (0 means 1)" % message.element_order)
    return {"size": message.mesh_size, "element_order": message.element_order or 1,
            "recombine": message.recombine}


def _mesh(message, context):
    options = _mesh_options(message, context)
    if message.mesh_content:
        if not message.mesh_extension:
            _fail(context, "mesh_extension", "is empty: give \".msh\" or \".geo\" with "
                  "mesh_content")
        return mesh_reader.read_mesh_content(message.mesh_content, message.mesh_extension,
                                             context + ": SetupBody.mesh_content", **options)
    if not message.mesh_path:
        _fail(context, "mesh_content", "and SetupBody.mesh_path are both empty: send the mesh")
    path = pathlib.Path(message.mesh_path)
    return mesh_reader.read_mesh(path, "%s: SetupBody.mesh_path: mesh file '%s'" % (context, path),
                                 **options)


def _check_boundary(mesh, name, context, field):
    if not name:
        _fail(context, field, "is empty: give the name of a physical curve")
    if name not in mesh.boundaries:
        known = ", ".join(sorted(mesh.boundaries)) or "none"
        _fail(context, field, "'%s' is not a boundary of the mesh (its boundaries: %s)" %
              (name, known))


def _dirichlet(message, mesh, context, field):
    _check_boundary(mesh, message.boundary, context, field + ".boundary")
    has_x, has_y = message.HasField("x"), message.HasField("y")
    if not has_x and not has_y:
        _fail(context, field, "prescribes neither x nor y: give at least one")
    x = message.x if has_x else None
    y = message.y if has_y else None
    if (x is not None and not math.isfinite(x)) or (y is not None and not math.isfinite(y)):
        _fail(context, field, "has a value that is not a finite number")
    return (message.boundary, x, y)


def _traction(message, mesh, context, field):
    _check_boundary(mesh, message.boundary, context, field + ".boundary")
    if not message.is_pressure:
        return (message.boundary, _vector(message.vector, context, field + ".vector"), None)
    if len(message.vector) != 0:
        _fail(context, field + ".vector", "is given with is_pressure = true: give one of them")
    if not math.isfinite(message.pressure):
        _fail(context, field + ".pressure", "is not a finite number")
    return (message.boundary, None, message.pressure)


def decode_setup_body(message, protocol):
    """(BodyDefinition, SolverSettings) of a SetupBody; `protocol` is the robin_pb2 module."""
    name = _body_name(message.body_name)
    context = "body '%s'" % name
    material = _material(message, protocol, context)
    body_force = (0.0, 0.0)
    if len(message.body_force):
        body_force = _vector(message.body_force, context, "body_force")
    settings = _solver(message.solver, context)
    mesh = _mesh(message, context)
    _check_boundary(mesh, message.contact_boundary, context, "contact_boundary")
    dirichlet = [_dirichlet(condition, mesh, context, "dirichlet[%d]" % k)
                 for k, condition in enumerate(message.dirichlet)]
    tractions = [_traction(condition, mesh, context, "traction[%d]" % k)
                 for k, condition in enumerate(message.traction)]
    definition = BodyDefinition(name, mesh, material, body_force, dirichlet, tractions,
                                message.contact_boundary)
    return definition, settings

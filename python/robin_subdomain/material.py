"""Linear elastic materials of plane problems: the 3x3 Voigt stiffness C with
stress (s_xx, s_yy, s_xy) = C (e_xx, e_yy, 2 e_xy), and the out-of-plane stress factor
s_zz = out_of_plane_poisson (s_xx + s_yy) (nu in isotropic plane strain, 0 otherwise).
Solid bodies (protocol 2.4): the 6x6 Voigt stiffness in the order (xx, yy, zz, yz, xz, xy) with
engineering shear strains, model SOLID.
"""

import math

import numpy as np

from .errors import InputError

PLANE_STRAIN, PLANE_STRESS, SOLID = "plane_strain", "plane_stress", "solid"


class Material:
    def __init__(self, stiffness, model, out_of_plane_poisson=0.0):
        self.stiffness = stiffness
        self.model = model
        self.out_of_plane_poisson = out_of_plane_poisson


def _number(value):
    return "%.12g" % value


def isotropic_material(young, poisson, model, context):
    """Plane strain: C = E/((1+nu)(1-2nu)) [[1-nu, nu, 0], [nu, 1-nu, 0], [0, 0, (1-2nu)/2]];
    plane stress: C = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]; solid:
    C = lambda 1 1' + 2 mu I on the normal components, mu on the shear ones,
    lambda = E nu/((1+nu)(1-2nu)), mu = E/(2(1+nu))."""
    if not math.isfinite(young) or young <= 0.0:
        raise InputError("%s: Young's modulus %s is not > 0: give a positive stiffness" %
                         (context, _number(young)))
    if not math.isfinite(poisson):
        raise InputError("%s: Poisson ratio %s is not a number" % (context, _number(poisson)))
    if poisson >= 0.5:
        raise InputError("%s: Poisson ratio %s is not < 0.5: the material is incompressible or "
                         "worse, which displacement-based elements cannot represent; use a value "
                         "below 0.5" % (context, _number(poisson)))
    if poisson <= -1.0:
        raise InputError("%s: Poisson ratio %s is not > -1: the material would not be stable; "
                         "use a value in (-1, 0.5)" % (context, _number(poisson)))
    nu = poisson
    if model == SOLID:
        lame = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        shear = young / (2.0 * (1.0 + nu))
        matrix = np.zeros((6, 6))
        matrix[:3, :3] = lame
        matrix[range(3), range(3)] += 2.0 * shear
        matrix[range(3, 6), range(3, 6)] = shear
        return Material(matrix, model, 0.0)
    if model == PLANE_STRAIN:
        factor = young / ((1.0 + nu) * (1.0 - 2.0 * nu))
        matrix = np.array([[1.0 - nu, nu, 0.0], [nu, 1.0 - nu, 0.0],
                           [0.0, 0.0, 0.5 * (1.0 - 2.0 * nu)]])
        return Material(matrix * factor, model, nu)
    factor = young / (1.0 - nu * nu)
    matrix = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
    return Material(matrix * factor, model, 0.0)


def voigt_material(values, model, context):
    """A full symmetric positive definite Voigt stiffness (row-major `values`): 3x3, or 6x6
    for a solid body."""
    size = 6 if model == SOLID else 3
    matrix = np.asarray(values, dtype=float).reshape(size, size)
    if not np.all(np.isfinite(matrix)):
        raise InputError("%s: the Voigt stiffness matrix has non-finite entries" % context)
    scale = np.max(np.abs(matrix))
    asymmetry = np.max(np.abs(matrix - matrix.T))
    if scale == 0.0 or asymmetry > 1e-12 * scale:
        raise InputError("%s: the Voigt stiffness matrix is not symmetric (largest |C_ij - C_ji| "
                         "= %s): give C_ij = C_ji" % (context, _number(asymmetry)))
    symmetric = 0.5 * (matrix + matrix.T)
    eigenvalues = np.linalg.eigvalsh(symmetric)
    if eigenvalues[0] <= 1e-12 * eigenvalues[-1]:
        raise InputError("%s: the Voigt stiffness matrix is not positive definite (smallest "
                         "eigenvalue %s, largest %s): the material would not be stable" %
                         (context, _number(eigenvalues[0]), _number(eigenvalues[-1])))
    return Material(symmetric, model, 0.0)


def stress_tensors(material, stress):
    """Voigt stresses (count x 3, or count x 6 for a solid) as symmetric tensors in ParaView's
    order (count x 6: XX, YY, ZZ, XY, YZ, XZ). Plane: s_zz = out_of_plane_poisson (s_xx + s_yy)
    (nu in isotropic plane strain, 0 otherwise), YZ = XZ = 0; solid: (xx, yy, zz, yz, xz, xy)
    reordered."""
    if stress.shape[1] == 6:
        return stress[:, [0, 1, 2, 5, 3, 4]].copy()
    tensors = np.zeros((len(stress), 6))
    tensors[:, [0, 1, 3]] = stress
    tensors[:, 2] = material.out_of_plane_poisson * (stress[:, 0] + stress[:, 1])
    return tensors


def von_mises(material, stress):
    """Von Mises stress of Voigt stresses (count x 3 or 6) as tensors (stress_tensors):
    sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2
         + 3 (s_xy^2 + s_yz^2 + s_xz^2))."""
    tensors = stress_tensors(material, stress)
    xx, yy, zz = tensors[:, 0], tensors[:, 1], tensors[:, 2]
    deviatoric = (xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2
    shear = tensors[:, 3] ** 2 + tensors[:, 4] ** 2 + tensors[:, 5] ** 2
    return np.sqrt(0.5 * deviatoric + 3.0 * shear)

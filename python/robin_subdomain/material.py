"""Linear elastic materials of plane problems: the 3x3 Voigt stiffness C with
stress (s_xx, s_yy, s_xy) = C (e_xx, e_yy, 2 e_xy), and the out-of-plane stress factor
s_zz = out_of_plane_poisson (s_xx + s_yy) (nu in isotropic plane strain, 0 otherwise).
"""

import math

import numpy as np

from .errors import InputError

PLANE_STRAIN, PLANE_STRESS = "plane_strain", "plane_stress"


class Material:
    def __init__(self, stiffness, model, out_of_plane_poisson=0.0):
        self.stiffness = stiffness
        self.model = model
        self.out_of_plane_poisson = out_of_plane_poisson


def _number(value):
    return "%.12g" % value


def isotropic_material(young, poisson, model, context):
    """Plane strain: C = E/((1+nu)(1-2nu)) [[1-nu, nu, 0], [nu, 1-nu, 0], [0, 0, (1-2nu)/2]];
    plane stress: C = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]."""
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
    if model == PLANE_STRAIN:
        factor = young / ((1.0 + nu) * (1.0 - 2.0 * nu))
        matrix = np.array([[1.0 - nu, nu, 0.0], [nu, 1.0 - nu, 0.0],
                           [0.0, 0.0, 0.5 * (1.0 - 2.0 * nu)]])
        return Material(matrix * factor, model, nu)
    factor = young / (1.0 - nu * nu)
    matrix = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
    return Material(matrix * factor, model, 0.0)


def voigt_material(values, model, context):
    """A full symmetric positive definite 3x3 Voigt stiffness (row-major `values`)."""
    matrix = np.asarray(values, dtype=float).reshape(3, 3)
    if not np.all(np.isfinite(matrix)):
        raise InputError("%s: the Voigt stiffness matrix has non-finite entries" % context)
    scale = np.max(np.abs(matrix))
    asymmetry = np.max(np.abs(matrix - matrix.T))
    if scale == 0.0 or asymmetry > 1e-12 * scale:
        raise InputError("%s: the Voigt stiffness matrix is not symmetric (largest |C_ij - C_ji| "
                         "= %s): give C_ij = C_ji" % (context, _number(asymmetry)))
    symmetric = 0.5 * (matrix + matrix.T)
    eigenvalues = np.linalg.eigvalsh(symmetric)
    if eigenvalues[0] <= 1e-12 * eigenvalues[2]:
        raise InputError("%s: the Voigt stiffness matrix is not positive definite (smallest "
                         "eigenvalue %s, largest %s): the material would not be stable" %
                         (context, _number(eigenvalues[0]), _number(eigenvalues[2])))
    return Material(symmetric, model, 0.0)


def von_mises(material, stress):
    """Von Mises stress of stresses (count x 3), with s_zz from the out-of-plane factor:
    sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 s_xy^2)."""
    xx, yy, xy = stress[:, 0], stress[:, 1], stress[:, 2]
    zz = material.out_of_plane_poisson * (xx + yy)
    deviatoric = (xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2
    return np.sqrt(0.5 * deviatoric + 3.0 * xy * xy)

"""Reference elements: quadrature rules and shape functions.

Reference triangle (0,0), (1,0), (0,1) (area 1/2); reference quadrilateral [-1, 1]^2 with
corners (-1,-1), (1,-1), (1,1), (-1,1); reference edge [-1, 1] with the endpoints at -1, 1 and
the midpoint (3-node lines) at 0. Solid cells (protocol 2.4): reference tetrahedron (0,0,0),
(1,0,0), (0,1,0), (0,0,1) (volume 1/6); reference hexahedron [-1, 1]^3, bottom face z = -1
counter-clockwise seen from above, then the top face. Node orders are Gmsh's. The rules are
those of the C++ server (subdomain/numerics/finite_element.cpp).
"""

import numpy as np

from .mesh import HEXAHEDRON8, LINE2, QUADRILATERAL4, TETRAHEDRON4, TRIANGLE3, TRIANGLE6


def gauss_legendre(point_count):
    """n-point Gauss-Legendre rule on [-1, 1] (exact to degree 2n - 1): points, weights."""
    return np.polynomial.legendre.leggauss(point_count)


def _orbit3(a, weight):
    # Barycentric orbit of (a, a, 1 - 2a).
    return [(a, a, weight), (1.0 - 2.0 * a, a, weight), (a, 1.0 - 2.0 * a, weight)]


def _orbit6(a, b, weight):
    # The 6 permutations of the barycentric point (a, b, 1 - a - b).
    c = 1.0 - a - b
    return [(r, s, weight) for r, s in ((a, b), (b, a), (b, c), (c, b), (a, c), (c, a))]


def _collapsed_triangle_rule(degree):
    # Duffy: x = u (1 - v), y = v on the unit square, Jacobian 1 - v.
    points, weights = gauss_legendre(degree // 2 + 2)
    rule = []
    for point_u, weight_u in zip(points, weights):
        for point_v, weight_v in zip(points, weights):
            u, v = 0.5 * (point_u + 1.0), 0.5 * (point_v + 1.0)
            rule.append((u * (1.0 - v), v, 0.25 * weight_u * weight_v * (1.0 - v)))
    return rule


def triangle_quadrature(degree):
    """Symmetric positive rules exact to `degree` (Strang-Fix 3, Dunavant 4-6): (points, weights)
    with weights summing to 1/2."""
    if degree <= 1:
        rule = [(1.0 / 3.0, 1.0 / 3.0, 0.5)]
    elif degree == 2:
        rule = _orbit3(1.0 / 6.0, 1.0 / 6.0)
    elif degree == 3:
        rule = _orbit6(0.659027622374092, 0.231933368553031, 1.0 / 12.0)
    elif degree == 4:
        rule = (_orbit3(0.4459484909159648, 0.11169079483900567) +
                _orbit3(0.09157621350977078, 0.054975871827661))
    elif degree == 5:
        root = np.sqrt(15.0)
        rule = ([(1.0 / 3.0, 1.0 / 3.0, 9.0 / 80.0)] +
                _orbit3((6.0 + root) / 21.0, (155.0 + root) / 2400.0) +
                _orbit3((6.0 - root) / 21.0, (155.0 - root) / 2400.0))
    elif degree == 6:
        rule = (_orbit3(0.24928674517087898, 0.058393137863215934) +
                _orbit3(0.06308901449150855, 0.02542245318510794) +
                _orbit6(0.053145049844795136, 0.31035245103380815, 0.041425537809171395))
    else:
        rule = _collapsed_triangle_rule(degree)
    table = np.array(rule)
    return table[:, :2], table[:, 2]


def quadrilateral_quadrature(degree):
    """Tensor Gauss rule with degree // 2 + 1 points per direction: (points, weights)."""
    points, weights = gauss_legendre(degree // 2 + 1)
    xi, eta = np.meshgrid(points, points)
    weight_xi, weight_eta = np.meshgrid(weights, weights)
    return np.column_stack([xi.ravel(), eta.ravel()]), (weight_xi * weight_eta).ravel()


def _collapsed_tetrahedron_rule(degree):
    # Duffy: x = u (1 - v)(1 - w), y = v (1 - w), z = w on the unit cube, Jacobian
    # (1 - v)(1 - w)^2.
    points, weights = gauss_legendre(degree // 2 + 2)
    rule = []
    for point_u, weight_u in zip(points, weights):
        for point_v, weight_v in zip(points, weights):
            for point_w, weight_w in zip(points, weights):
                u, v, w = 0.5 * (point_u + 1.0), 0.5 * (point_v + 1.0), 0.5 * (point_w + 1.0)
                weight = 0.125 * weight_u * weight_v * weight_w * (1.0 - v) * (1.0 - w) ** 2
                rule.append((u * (1.0 - v) * (1.0 - w), v * (1.0 - w), w, weight))
    return rule


def tetrahedron_quadrature(degree):
    """The centroid rule (degree 1), the symmetric 4-point rule (degree 2), else the collapsed
    Gauss rule: (points, weights) with weights summing to 1/6."""
    if degree <= 1:
        rule = [(0.25, 0.25, 0.25, 1.0 / 6.0)]
    elif degree == 2:
        a = (5.0 - np.sqrt(5.0)) / 20.0
        b = 1.0 - 3.0 * a
        rule = [(a, a, a, 1.0 / 24.0), (b, a, a, 1.0 / 24.0), (a, b, a, 1.0 / 24.0),
                (a, a, b, 1.0 / 24.0)]
    else:
        rule = _collapsed_tetrahedron_rule(degree)
    table = np.array(rule)
    return table[:, :3], table[:, 3]


def hexahedron_quadrature(degree):
    """Tensor Gauss rule with degree // 2 + 1 points per direction, xi fastest."""
    points, weights = gauss_legendre(degree // 2 + 1)
    zeta, eta, xi = np.meshgrid(points, points, points, indexing="ij")
    weight_zeta, weight_eta, weight_xi = np.meshgrid(weights, weights, weights, indexing="ij")
    return (np.column_stack([xi.ravel(), eta.ravel(), zeta.ravel()]),
            (weight_xi * weight_eta * weight_zeta).ravel())


def element_quadrature(element_type, degree):
    if element_type == QUADRILATERAL4:
        return quadrilateral_quadrature(degree)
    if element_type == TETRAHEDRON4:
        return tetrahedron_quadrature(degree)
    if element_type == HEXAHEDRON8:
        return hexahedron_quadrature(degree)
    return triangle_quadrature(degree)


def edge_quadrature(degree):
    """Gauss-Legendre with degree // 2 + 1 points on [-1, 1]."""
    return gauss_legendre(degree // 2 + 1)


QUADRILATERAL_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
HEXAHEDRON_CORNERS = np.array([[-1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [1.0, 1.0, -1.0],
                               [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0],
                               [1.0, 1.0, 1.0], [-1.0, 1.0, 1.0]])
TETRAHEDRON_CORNERS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
                                [0.0, 0.0, 1.0]])


def reference_nodes(element_type):
    if element_type == TETRAHEDRON4:
        return TETRAHEDRON_CORNERS.copy()
    if element_type == HEXAHEDRON8:
        return HEXAHEDRON_CORNERS.copy()
    if element_type == TRIANGLE3:
        return np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    if element_type == TRIANGLE6:
        return np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])
    return QUADRILATERAL_CORNERS.copy()


def reference_centroid(element_type):
    if element_type == QUADRILATERAL4:
        return np.array([0.0, 0.0])
    if element_type == TETRAHEDRON4:
        return np.array([0.25, 0.25, 0.25])
    if element_type == HEXAHEDRON8:
        return np.array([0.0, 0.0, 0.0])
    return np.array([1.0 / 3.0, 1.0 / 3.0])


def _solid_shape_functions(element_type, reference):
    r, s, t = reference
    if element_type == TETRAHEDRON4:
        return (np.array([1.0 - r - s - t, r, s, t]),
                np.array([[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    # N_i = (1 + xi_i xi)(1 + eta_i eta)(1 + zeta_i zeta) / 8
    along = 1.0 + HEXAHEDRON_CORNERS * np.array([r, s, t])           # 8 x 3
    values = 0.125 * along[:, 0] * along[:, 1] * along[:, 2]
    gradients = 0.125 * HEXAHEDRON_CORNERS * np.column_stack(
        [along[:, 1] * along[:, 2], along[:, 0] * along[:, 2], along[:, 0] * along[:, 1]])
    return values, gradients


def shape_functions(element_type, reference):
    """Values N (k) and reference gradients dN/dxi (k x d) at one reference point."""
    if element_type in (TETRAHEDRON4, HEXAHEDRON8):
        return _solid_shape_functions(element_type, reference)
    r, s = reference
    if element_type == TRIANGLE3:
        return (np.array([1.0 - r - s, r, s]),
                np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]))
    if element_type == TRIANGLE6:
        # Barycentric l0 = 1 - r - s; corners l_i (2 l_i - 1); midpoints of edges 01, 12, 20:
        # 4 l0 l1, 4 l1 l2, 4 l2 l0.
        l0 = 1.0 - r - s
        values = np.array([l0 * (2.0 * l0 - 1.0), r * (2.0 * r - 1.0), s * (2.0 * s - 1.0),
                           4.0 * l0 * r, 4.0 * r * s, 4.0 * s * l0])
        gradients = np.array([[1.0 - 4.0 * l0, 1.0 - 4.0 * l0], [4.0 * r - 1.0, 0.0],
                              [0.0, 4.0 * s - 1.0], [4.0 * (l0 - r), -4.0 * r],
                              [4.0 * s, 4.0 * r], [-4.0 * s, 4.0 * (l0 - s)]])
        return values, gradients
    # N_i = (1 + xi_i xi)(1 + eta_i eta) / 4
    along_xi = 1.0 + QUADRILATERAL_CORNERS[:, 0] * r
    along_eta = 1.0 + QUADRILATERAL_CORNERS[:, 1] * s
    values = 0.25 * along_xi * along_eta
    gradients = 0.25 * np.column_stack([QUADRILATERAL_CORNERS[:, 0] * along_eta,
                                        QUADRILATERAL_CORNERS[:, 1] * along_xi])
    return values, gradients


def edge_shape_functions(edge_type, t):
    """Values and derivatives d/dt on the reference edge at t."""
    if edge_type == LINE2:
        return np.array([0.5 * (1.0 - t), 0.5 * (1.0 + t)]), np.array([-0.5, 0.5])
    return (np.array([0.5 * t * (t - 1.0), 0.5 * t * (t + 1.0), 1.0 - t * t]),
            np.array([t - 0.5, t + 0.5, -2.0 * t]))


def edge_reference_nodes(edge_type):
    return [-1.0, 1.0] if edge_type == LINE2 else [-1.0, 1.0, 0.0]

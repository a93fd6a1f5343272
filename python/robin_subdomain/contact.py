"""The dual contact problem of one body and its bound-constrained QP solver.

Local contact problem (paper step 1): minimise 1/2 u'Ku - f'u subject to B u <= g, solved in its
dual form
    minimise q(lambda) = 1/2 lambda'F lambda - lambda'(e - g)   subject to lambda >= 0,
whose gradient F lambda - (e - g) = g - u_N. Its KKT conditions are the Signorini conditions
lambda >= 0, u_N <= g, lambda_i (g_i - u_N,i) = 0.

Solver (solve_bound_qp): a primal-dual active set method (a semismooth Newton method on
min(lambda, gradient / diag F) = 0): on the guessed free set I solve F_II lambda_I = b_I exactly
(Cholesky), set lambda = 0 elsewhere, and re-guess I from the signs of lambda and the gradient.
It usually ends in a few steps, but F (dense, positive entries) is not an M-matrix, so it may
cycle; a repeated set, or too many steps, hands over to the safeguard: the Lawson-Hanson primal
active set method, which decreases q monotonically and terminates finitely (each step is the
exact minimiser over a face, moves to the face boundary when it leaves the feasible set, and
frees one constraint with a negative gradient at a time).
Stopping: the projected gradient g^P (g_i where lambda_i > 0, min(g_i, 0) where lambda_i = 0)
satisfies ||g^P|| <= tolerance ||F|| ||lambda|| (||e - g|| while lambda = 0), the solution-scaled
criterion of the C++ server.
"""

import time

import numpy as np
import scipy.linalg
import scipy.sparse


CONVERGED, NOT_CONVERGED, BREAKDOWN = "CONVERGED", "NOT_CONVERGED", "BREAKDOWN"
COLUMN_BLOCK = 16  # SuperLU solves are fastest per column with about 16 right-hand sides


class QpResult:
    def __init__(self, solution, gradient, status, iterations, projected_gradient_norm, message):
        self.solution = solution
        self.gradient = gradient
        self.status = status
        self.iterations = iterations
        self.projected_gradient_norm = projected_gradient_norm
        self.message = message


def projected_gradient(solution, gradient):
    """g^P: g_i on the free set (lambda_i > 0), min(g_i, 0) on the active set."""
    return np.where(solution > 0.0, gradient, np.minimum(gradient, 0.0))


def estimate_norm(matrix, iterations=30):
    """||F||_2 of a symmetric positive semidefinite matrix, by power iterations from a fixed
    start (a lower estimate; used only as the scale of the stopping test)."""
    size = len(matrix)
    if size == 0:
        return 0.0
    vector = np.cos(np.arange(1, size + 1) * 0.7548776662466927) + 1.0
    vector /= np.linalg.norm(vector)
    norm = 0.0
    for _ in range(iterations):
        product = matrix @ vector
        norm = np.linalg.norm(product)
        if not norm > 0.0:
            return norm
        vector = product / norm
    return norm


def _face_minimiser(matrix, right_hand_side, free):
    """z with z_I = F_II^-1 b_I (Cholesky plus one refinement step) and z = 0 elsewhere."""
    solution = np.zeros(len(right_hand_side))
    if not np.any(free):
        return solution
    block = matrix[np.ix_(free, free)]
    factor = scipy.linalg.cho_factor(block, lower=False, check_finite=False)
    local = scipy.linalg.cho_solve(factor, right_hand_side[free], check_finite=False)
    residual = right_hand_side[free] - block @ local
    local += scipy.linalg.cho_solve(factor, residual, check_finite=False)
    solution[free] = local
    return solution


class _Problem:
    """min 1/2 x'Fx - b'x, x >= 0, with the stopping threshold of the module comment."""

    def __init__(self, matrix, right_hand_side, tolerance, norm):
        self.matrix = matrix
        self.right_hand_side = right_hand_side
        self.tolerance = tolerance
        self.norm = norm
        self.size = len(right_hand_side)

    def gradient(self, x):
        return self.matrix @ x - self.right_hand_side

    def threshold(self, x):
        scale = self.norm * np.linalg.norm(x)
        if not scale > 0.0:
            scale = np.linalg.norm(self.right_hand_side)
        return max(self.tolerance * scale, 1e-300)

    def sign_margin(self, x):
        """|g_i| below which a constraint is not worth freeing (rounding level of the test)."""
        return 0.1 * self.threshold(x) / np.sqrt(max(self.size, 1))


def _primal_dual_active_set(problem, x, max_steps):
    """Returns (x, steps, converged). x is feasible on return."""
    diagonal = np.diag(problem.matrix)
    diagonal = np.where(diagonal > 0.0, diagonal, 1.0)
    gradient = problem.gradient(x)
    free = x - gradient / diagonal > 0.0
    seen = set()
    for step in range(1, max_steps + 1):
        key = np.packbits(free).tobytes()
        if key in seen:
            return np.maximum(x, 0.0), step, False
        seen.add(key)
        x = _face_minimiser(problem.matrix, problem.right_hand_side, free)
        gradient = problem.gradient(x)
        margin = problem.sign_margin(x)
        new_free = (free & (x > 0.0)) | (~free & (gradient < -margin))
        if np.array_equal(new_free, free):
            return x, step, True
        free = new_free
    return np.maximum(x, 0.0), max_steps, False


def _move_to_face_minimiser(problem, x, free):
    """Lawson-Hanson inner loop: from feasible x with x > 0 on `free`, step towards the face
    minimiser and drop the constraints that block it, until the face minimiser is feasible."""
    while True:
        z = _face_minimiser(problem.matrix, problem.right_hand_side, free)
        blocking = free & (z <= 0.0)
        if not np.any(blocking):
            return z, free
        ratios = x[blocking] / (x[blocking] - z[blocking])
        alpha = np.min(ratios)
        x = x + alpha * (z - x)
        released = blocking.copy()
        released[blocking] = ratios <= alpha
        x[released | (x <= 0.0)] = 0.0
        free = free & (x > 0.0)


def _lawson_hanson(problem, x, max_steps):
    """Returns (x, steps, converged) from a feasible start."""
    free = x > 0.0
    x, free = _move_to_face_minimiser(problem, x, free)
    for step in range(1, max_steps + 1):
        gradient = problem.gradient(x)
        candidates = np.where(~free, gradient, np.inf)
        best = int(np.argmin(candidates))
        if not candidates[best] < -problem.sign_margin(x):
            return x, step, True
        previous = free.copy()
        free[best] = True
        x, free = _move_to_face_minimiser(problem, x, free)
        if np.array_equal(free, previous):
            # The freed constraint was dropped again at once: no descent left above the
            # rounding level; the caller's projected-gradient test decides.
            return x, step, True
    return x, max_steps, False


def solve_bound_qp(matrix, right_hand_side, start, tolerance, max_iterations, norm):
    """Minimises 1/2 x'Fx - b'x over x >= 0 from `start` (projected). See the module comment."""
    problem = _Problem(matrix, right_hand_side, tolerance, norm)
    if problem.size == 0:
        return QpResult(np.zeros(0), np.zeros(0), CONVERGED, 0, 0.0, "")
    x = np.maximum(np.asarray(start, dtype=float), 0.0)
    try:
        x, steps, converged = _primal_dual_active_set(problem, x, min(50, max_iterations))
        if not converged:
            x, more, converged = _lawson_hanson(problem, x, max_iterations - steps)
            steps += more
    except (np.linalg.LinAlgError, ValueError) as error:
        gradient = problem.gradient(x)
        return QpResult(x, gradient, BREAKDOWN, 0,
                        float(np.linalg.norm(projected_gradient(x, gradient))),
                        "the compliance is not positive definite on the free set: %s" % error)
    gradient = problem.gradient(x)
    norm_projected = float(np.linalg.norm(projected_gradient(x, gradient)))
    if not (np.all(np.isfinite(x)) and np.isfinite(norm_projected)):
        return QpResult(x, gradient, BREAKDOWN, steps, norm_projected,
                        "non-finite iterate or gradient after %d iterations" % steps)
    threshold = problem.threshold(x)
    if norm_projected <= threshold:
        return QpResult(x, gradient, CONVERGED, steps, norm_projected, "")
    reason = ("no convergence in %d iterations" % max_iterations if not converged else
              "the tolerance is below the attainable accuracy")
    return QpResult(x, gradient, NOT_CONVERGED, steps, norm_projected,
                    "%s: ||g^P|| = %.3g > %.3g" % (reason, norm_projected, threshold))


class ContactInterface:
    """B, e, F and the warm start of one contact assignment (a ContactOperator) of `body`:
    trace = B on the free dofs (rows x free), prescribed_trace = B u_p (rows),
    full_operator = B on all dofs (rows x dn), free_trace e, compliance F.

    It keeps the body's factor and reduced load, not the body: the body holds its
    ContactInterface (Body.contact), and a reference back would make each body a reference
    cycle, freed (with its factor and matrices) only by an occasional full garbage collection,
    which lets a server's memory grow run after run."""

    def __init__(self, body, operator):
        start = time.perf_counter()
        self.factor = body.factor                 # K^-1 of the body (its sparse LU)
        self.reduced_load = body.reduced_load     # f_f - K_fp u_p
        self.operator = operator
        count = operator.row_count
        dofs = operator.dofs()
        prescribed = body.is_prescribed[dofs]
        # B u_p, and B on the free dofs (rows x free)
        self.prescribed_trace = np.zeros(count)
        np.add.at(self.prescribed_trace, operator.entry_rows[prescribed],
                  operator.values[prescribed] * body.prescribed[dofs[prescribed]])
        free = ~prescribed
        self.trace = scipy.sparse.csr_matrix(
            (operator.values[free], (operator.entry_rows[free], body.free_index[dofs[free]])),
            shape=(count, body.free_dof_count()))
        self.full_operator = scipy.sparse.csr_matrix(
            (operator.values, (operator.entry_rows, dofs)), shape=(count, len(body.prescribed)))
        self.unit_free_trace = self.trace @ body.free_solution + self.prescribed_trace  # e
        self.load_factor = 1.0
        self.free_trace = self.unit_free_trace
        self.compliance = self._dense_compliance()
        self.norm = estimate_norm(self.compliance)
        self.warm_start = np.zeros(count)
        self.seconds = time.perf_counter() - start

    def set_load_factor(self, factor):
        """Since protocol 2.1: e = t e_1 for the load factor t (f and u_p scale with t)."""
        self.load_factor = factor
        self.free_trace = factor * self.unit_free_trace

    def nodal_forces(self, contact_force):
        """B' lambda on every dof (dn): minus the contact forces acting on the body."""
        return self.full_operator.T @ contact_force

    def _dense_compliance(self):
        """F = B K^-1 B', COLUMN_BLOCK columns per block of solves, symmetrised."""
        count = self.trace.shape[0]
        transpose = self.trace.T.tocsc()
        compliance = np.empty((count, count))
        for first in range(0, count, COLUMN_BLOCK):
            loads = transpose[:, first:first + COLUMN_BLOCK].toarray()
            compliance[:, first:first + COLUMN_BLOCK] = self.trace @ self.factor.solve(loads)
        return 0.5 * (compliance + compliance.T)

    def size(self):
        """The number of constraints (rows of B)."""
        return self.operator.row_count

    def solve_contact(self, obstacle, tolerance, max_iterations):
        """Step 1 with obstacle g, warm-started. Returns a dict of the ContactSolveResult values."""
        start = time.perf_counter()
        qp = solve_bound_qp(self.compliance, self.free_trace - obstacle, self.warm_start,
                            tolerance, max_iterations, self.norm)
        normal_trace = obstacle - qp.gradient        # u_N = g - (F lambda - (e - g))
        clearance = obstacle - normal_trace
        if qp.status == CONVERGED:
            self.warm_start = qp.solution.copy()
        return {"normal_trace": normal_trace, "contact_force": qp.solution,
                "active": qp.solution > 0.0, "status": qp.status, "iterations": qp.iterations,
                "projected_gradient_norm": qp.projected_gradient_norm,
                "penetration": float(max(0.0, np.max(-clearance, initial=0.0))),
                "complementarity": float(np.max(np.abs(qp.solution * clearance), initial=0.0)),
                "seconds": time.perf_counter() - start, "message": qp.message}

    def solve_correction(self, interface_force):
        """Step 2: w_N = B w with K w = B' r (homogeneous Dirichlet conditions), = F r."""
        return self.compliance @ interface_force

    def solve_neumann(self, contact_force):
        """The Neumann solve (since protocol 1.1): u_N = B u with K u = f - B' lambda, u = u_p
        on the prescribed dofs. One solve with the body's factor, not e - F lambda (so that it
        is an independent check of F and e)."""
        load = self.load_factor * self.reduced_load - self.trace.T @ contact_force
        return self.trace @ self.factor.solve(load) + self.load_factor * self.prescribed_trace

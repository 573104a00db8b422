"""Reference least-squares problems with known answers, for tests, demos and benchmarks.

Each problem comes in every form the solvers take: numpy residual and Jacobian
(:func:`~solvers.gauss_newton`), a vectorised population cost (the swarms) and a CasADi
residual with its data matrix (:func:`~solvers.casadi_lsq`), together with the parameters
that generated it (as qpsolvers' ``problems.py``).
"""

from __future__ import annotations

import casadi
import numpy as np
from scipy.spatial.transform import Rotation

from solvers.problem import LeastSquaresProblem


def sphere_fit(n_points: int = 200, noise: float = 1e-3, seed: int = 0) -> LeastSquaresProblem:
    """Fit a sphere (centre c, radius ρ) to noisy points: ``r_k = ||a_k − c|| − ρ``.

    Args:
        n_points: Number of points N (= M residuals), spread over the whole sphere.
        noise: Standard deviation of the Gaussian noise added to each point coordinate (m).
        seed: Seed of the generator.

    Returns:
        Unknowns ``x = (c_x, c_y, c_z, ρ)`` in metres, ``x_true = (0.1, −0.2, 0.3, 0.5)``;
        ``data`` holds the points, shape (3, N).
    """
    rng = np.random.default_rng(seed)
    x_true = np.array([0.1, -0.2, 0.3, 0.5])
    u = rng.normal(size=(n_points, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    points = x_true[:3] + x_true[3] * u + noise * rng.normal(size=(n_points, 3))

    def residual(x: np.ndarray) -> np.ndarray:
        return np.asarray(np.linalg.norm(points - x[:3], axis=1) - x[3])

    def jacobian(x: np.ndarray) -> np.ndarray:
        diff = points - x[:3]
        unit = diff / np.linalg.norm(diff, axis=1, keepdims=True)
        return np.hstack([-unit, -np.ones((n_points, 1))])

    def cost_batch(X: np.ndarray) -> np.ndarray:
        dist = np.linalg.norm(points[None, :, :] - X[:, None, :3], axis=2)
        r = dist - X[:, 3:4]
        return np.asarray(0.5 * np.sum(r * r, axis=1))

    xs = casadi.SX.sym("x", 4)
    ps = casadi.SX.sym("p", 3)
    fun = casadi.Function("sphere_fit_residual", [xs, ps], [casadi.norm_2(ps - xs[:3]) - xs[3]])
    return LeastSquaresProblem(
        name="sphere_fit",
        residual=residual,
        jacobian=jacobian,
        cost_batch=cost_batch,
        casadi_residual=fun,
        data=points.T.copy(),
        x_true=x_true,
        x0=x_true + np.array([0.05, -0.04, 0.03, 0.1]),
        lower=np.array([-1.0, -1.0, -1.0, 0.05]),
        upper=np.array([1.0, 1.0, 1.0, 2.0]),
    )


def shared_point_acceleration(
    n_samples: int = 2000, noise: float = 0.05, seed: int = 0
) -> LeastSquaresProblem:
    """Two rigid bodies share one point; find it in both body frames (6 unknowns).

    Body A measures the acceleration ``a_k`` of its origin, its angular velocity ``ω_k`` and
    angular acceleration ``α_k``; body B likewise ``b_k, ν_k, β_k``. The point ``c₁`` (in
    A) coincides with ``c₂`` (in B), so its acceleration has the same norm in both frames::

        r_k = ||a_k + ω_k×(ω_k×c₁) + α_k×c₁|| − ||b_k + ν_k×(ν_k×c₂) + β_k×c₂||.

    (The joint-centre problem of Hu et al. 2021, eq. 1–3, with ``c = −V``.) The data are
    random: angular rates ~ N(0, 2 rad/s), angular accelerations ~ N(0, 15 rad/s²),
    point accelerations ~ N(0, 4 m/s²) + gravity, a random relative rotation per sample, and
    white noise of ``noise`` m/s² on each acceleration coordinate.

    Args:
        n_samples: Number of samples N (= M residuals).
        noise: Standard deviation of the accelerometer noise (m/s²).
        seed: Seed of the generator.

    Returns:
        Unknowns ``x = (c₁, c₂)`` in metres; ``data`` has shape (18, N), rows
        ``a, ω, α, b, ν, β`` (3 each); search box ±0.25 m.
    """
    rng = np.random.default_rng(seed)
    N = n_samples
    x_true = np.array([0.10, -0.15, 0.05, -0.08, 0.17, 0.03])
    w_a, w_b = rng.normal(0.0, 2.0, (N, 3)), rng.normal(0.0, 2.0, (N, 3))
    al_a, al_b = rng.normal(0.0, 15.0, (N, 3)), rng.normal(0.0, 15.0, (N, 3))
    j_a = rng.normal(0.0, 4.0, (N, 3)) + np.array([0.0, 0.0, 9.81])
    R_ab = Rotation.random(N, random_state=rng).as_matrix()
    j_b = np.einsum("nji,nj->ni", R_ab, j_a)
    K_a, K_b = _gamma_matrices(w_a, al_a), _gamma_matrices(w_b, al_b)
    a = j_a - np.einsum("nij,j->ni", K_a, x_true[:3]) + noise * rng.normal(size=(N, 3))
    b = j_b - np.einsum("nij,j->ni", K_b, x_true[3:]) + noise * rng.normal(size=(N, 3))

    def residual(x: np.ndarray) -> np.ndarray:
        u = a + np.einsum("nij,j->ni", K_a, x[:3])
        v = b + np.einsum("nij,j->ni", K_b, x[3:])
        return np.asarray(np.linalg.norm(u, axis=1) - np.linalg.norm(v, axis=1))

    def jacobian(x: np.ndarray) -> np.ndarray:
        u = a + np.einsum("nij,j->ni", K_a, x[:3])
        v = b + np.einsum("nij,j->ni", K_b, x[3:])
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        return np.hstack([np.einsum("ni,nij->nj", u, K_a), -np.einsum("ni,nij->nj", v, K_b)])

    K_a_rows, K_b_rows = K_a.reshape(3 * N, 3).T.copy(), K_b.reshape(3 * N, 3).T.copy()
    a_row, b_row = a.reshape(-1), b.reshape(-1)

    def cost_batch(X: np.ndarray) -> np.ndarray:
        U = X[:, :3] @ K_a_rows  # (P, 3N): one GEMM for the whole population
        U += a_row
        V = X[:, 3:] @ K_b_rows
        V += b_row
        U3, V3 = U.reshape(len(X), N, 3), V.reshape(len(X), N, 3)
        r = np.sqrt(np.einsum("pnk,pnk->pn", U3, U3)) - np.sqrt(np.einsum("pnk,pnk->pn", V3, V3))
        return np.asarray(0.5 * np.einsum("pn,pn->p", r, r))

    xs = casadi.SX.sym("x", 6)
    ps = casadi.SX.sym("p", 18)
    blocks = [ps[3 * i : 3 * i + 3] for i in range(6)]

    def gamma(w: casadi.SX, al: casadi.SX, c: casadi.SX) -> casadi.SX:
        return casadi.cross(w, casadi.cross(w, c)) + casadi.cross(al, c)

    e = casadi.norm_2(blocks[0] + gamma(blocks[1], blocks[2], xs[:3])) - casadi.norm_2(
        blocks[3] + gamma(blocks[4], blocks[5], xs[3:])
    )
    return LeastSquaresProblem(
        name="shared_point_acceleration",
        residual=residual,
        jacobian=jacobian,
        cost_batch=cost_batch,
        casadi_residual=casadi.Function("shared_point_residual", [xs, ps], [e]),
        data=np.vstack([a.T, w_a.T, al_a.T, b.T, w_b.T, al_b.T]),
        x_true=x_true,
        x0=x_true + np.array([0.04, 0.03, -0.05, -0.03, 0.04, 0.05]),
        lower=np.full(6, -0.25),
        upper=np.full(6, 0.25),
    )


def rosenbrock(n: int = 2) -> LeastSquaresProblem:
    """Rosenbrock's function as least squares: ``r = (10 (x_{i+1} − x_i²), 1 − x_i)``.

    Args:
        n: Number of unknowns (>= 2); M = 2 (n − 1) residuals.

    Returns:
        ``x_true = (1, …, 1)``, ``x0 = (−1.2, 1, 1, …, 1)``, box [−2, 2]ⁿ; the CasADi
        residual takes ``x`` only (``data`` is ``None``). For 4 <= n <= 7 the function also
        has a local minimum near ``x_1 = −1``, a trap for local solvers.
    """
    if n < 2:
        raise ValueError(f"rosenbrock needs n >= 2 unknowns, got {n}")
    m = n - 1

    def residual(x: np.ndarray) -> np.ndarray:
        return np.concatenate([10.0 * (x[1:] - x[:-1] ** 2), 1.0 - x[:-1]])

    def jacobian(x: np.ndarray) -> np.ndarray:
        J = np.zeros((2 * m, n))
        i = np.arange(m)
        J[i, i] = -20.0 * x[:-1]
        J[i, i + 1] = 10.0
        J[m + i, i] = -1.0
        return J

    def cost_batch(X: np.ndarray) -> np.ndarray:
        r1 = 10.0 * (X[:, 1:] - X[:, :-1] ** 2)
        r2 = 1.0 - X[:, :-1]
        return np.asarray(0.5 * (np.sum(r1 * r1, axis=1) + np.sum(r2 * r2, axis=1)))

    xs = casadi.SX.sym("x", n)
    r = casadi.vertcat(10.0 * (xs[1:] - xs[:-1] ** 2), 1.0 - xs[:-1])
    x0 = np.ones(n)
    x0[0] = -1.2
    return LeastSquaresProblem(
        name="rosenbrock",
        residual=residual,
        jacobian=jacobian,
        cost_batch=cost_batch,
        casadi_residual=casadi.Function("rosenbrock_residual", [xs], [r]),
        data=None,
        x_true=np.ones(n),
        x0=x0,
        lower=np.full(n, -2.0),
        upper=np.full(n, 2.0),
    )


def _gamma_matrices(w: np.ndarray, al: np.ndarray) -> np.ndarray:
    """``K`` with ``K c = ω×(ω×c) + α×c = (ω ωᵀ − |ω|² I + [α]×) c``; shapes (N, 3) → (N, 3, 3)."""
    K = np.einsum("ni,nj->nij", w, w) - np.einsum("n,ij->nij", np.sum(w * w, axis=1), np.eye(3))
    K[:, 0, 1] -= al[:, 2]
    K[:, 0, 2] += al[:, 1]
    K[:, 1, 0] += al[:, 2]
    K[:, 1, 2] -= al[:, 0]
    K[:, 2, 0] -= al[:, 1]
    K[:, 2, 1] += al[:, 0]
    return K

"""Nadaraya–Watson kernel regression on one or two joint angles (Lee & Lee 2022, §2.2, M2/M3).

``y = f(x)`` with ``x`` (N, D), D = 1 (M2: the flexion of the joint) or D = 2
(M3: two angles), and ``y`` (N, K) the S2J components (K = 6 for
``[s_prox; s_dist]``). The estimator (Nadaraya 1964) is

    f*(x) = Σ_i K_h(x − x_i) y_i / Σ_i K_h(x − x_i),

with a Gaussian product kernel ``K_h(u) = Π_d exp(−½ (u_d / h_d)²)``.

Choices the paper leaves open, written down:

- **Grid.** The training inputs are binned to the nearest node of a regular
  grid spanning their range (default 61 nodes for one input, 31 × 31 for
  two); each occupied node keeps the sample count and the mean output, and
  the estimator sums over nodes instead of samples. The fitted model is
  small enough for a JSON sidecar whatever the training length. The binning
  moves each input by at most half a node spacing, and the bandwidth is
  never below one spacing.
- **Prediction.** The estimate is evaluated once at every grid node and
  interpolated multilinearly (linear in 1-D, bilinear in 2-D) at the
  queries: O(N_query) and vectorised. The interpolation error is second
  order in the node spacing, below the kernel's own smoothing.
- **Bandwidth.** One bandwidth per input, shared by the K outputs, chosen by
  *leave-one-node-out* cross-validation: each occupied node is predicted
  from all the other nodes, and the candidate with the smallest squared
  error summed over samples and outputs wins. Leaving out a whole node,
  rather than one sample, matters for time series: consecutive samples are
  nearly equal and land in the same node, so leave-one-sample-out CV would
  always pick the smallest bandwidth. Candidates run geometrically from one
  node spacing to half the input range (14 per input; all pairs for two
  inputs). Nodes whose prediction has no support from other nodes are
  scored as if predicted by the global mean, which penalises bandwidths
  too narrow to bridge gaps.
- **Extrapolation.** Queries are clamped to the training range of each
  input (the estimate stays at its value at the edge). Between and beyond
  training data, the kernel weights are normalised by their largest value
  before exponentiation, so a query far from every node takes the output of
  the nearest nodes instead of 0/0. Consequently, in two dimensions a
  combination of angles never seen in training is answered by the closest
  combination seen — the 2-D analogue of clamping to the edge.
- **Boundary bias.** Near the ends of the training range the estimate
  averages samples from one side only and is biased towards the interior
  by about ``slope × h`` (Nadaraya–Watson's known weakness; a local-linear
  fit would remove it). With the bandwidths chosen here this is a fraction
  of a millimetre for S2J vectors.
- The paper's M3 used a polynomial surface (polyfitn, its ref. 35); a kernel
  surface is used here instead so that M2 and M3 share one estimator and
  extrapolation stays bounded.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError, ShapeError

#: Format tag of :meth:`KernelRegression.to_dict`.
FORMAT = "lowerlimb-kernel-regression/1"
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class KernelRegressionParams:
    """Settings of :func:`fit_kernel_regression`.

    Attributes:
        grid_size: nodes per input; ``None`` = 61 for one input, 31 for two.
        n_bandwidths: bandwidth candidates per input for the cross-validation.
        bandwidth: fixed bandwidth per input (same unit as the inputs, rad
            for angles); skips the cross-validation when given.
        min_samples: fewest training samples accepted.
    """

    grid_size: int | None = None
    n_bandwidths: int = 14
    bandwidth: tuple[float, ...] | None = None
    min_samples: int = 10


@dataclass(frozen=True)
class KernelRegression:
    """A fitted Nadaraya–Watson regression on a regular grid (see the module docstring).

    Attributes:
        lower: (D,) lower end of the training range of each input (rad for angles).
        upper: (D,) upper end of the training range of each input.
        grid_size: nodes per input (1 for an input with no spread).
        bandwidth: (D,) Gaussian kernel standard deviation per input.
        nodes: (M,) flat (C-order) indices of the occupied grid nodes.
        counts: (M,) training samples per occupied node.
        means: (M, K) mean output of the samples of each occupied node.
        cv_rms: cross-validated RMS error per output component at the chosen
            bandwidth (output unit, m for S2J vectors).
    """

    lower: FloatArray
    upper: FloatArray
    grid_size: tuple[int, ...]
    bandwidth: FloatArray
    nodes: IntArray
    counts: FloatArray
    means: FloatArray
    cv_rms: float

    @property
    def n_inputs(self) -> int:
        """Number of inputs D."""
        return len(self.grid_size)

    @property
    def n_outputs(self) -> int:
        """Number of outputs K."""
        return int(self.means.shape[1])

    def node_positions(self) -> FloatArray:
        """(M, D) input values of the occupied nodes."""
        axes = _axes(self.lower, self.upper, self.grid_size)
        idx = np.unravel_index(self.nodes, self.grid_size)
        return np.stack([axes[d][idx[d]] for d in range(self.n_inputs)], axis=1)

    def predict(self, x: ArrayLike) -> FloatArray:
        """Evaluate the regression at the query inputs.

        Queries are clamped to the training range; the grid-node estimates
        (:attr:`grid_values`) are interpolated multilinearly.

        Args:
            x: (N, D) query inputs (or (N,) when D = 1), same unit as in training.

        Returns:
            (N, K) estimated outputs.

        Raises:
            ShapeError: when ``x`` does not have D columns.
            InputError: on NaN or infinite values.
        """
        q = _inputs("x", x, self.n_inputs)
        q = np.clip(q, self.lower, self.upper)
        values = self.grid_values
        # multilinear interpolation between the grid nodes
        out = np.zeros((q.shape[0], self.n_outputs))
        base, frac = [], []
        for k in range(self.n_inputs):
            g = self.grid_size[k]
            if g == 1:
                base.append(np.zeros(q.shape[0], dtype=np.int64))
                frac.append(np.zeros(q.shape[0]))
                continue
            u = (q[:, k] - self.lower[k]) / (self.upper[k] - self.lower[k]) * (g - 1)
            i0 = np.clip(np.floor(u).astype(np.int64), 0, g - 2)
            base.append(i0)
            frac.append(u - i0)
        for corner in np.ndindex(*(2,) * self.n_inputs):
            weight = np.ones(q.shape[0])
            index = []
            for k, c in enumerate(corner):
                if self.grid_size[k] == 1:
                    if c == 1:
                        weight = weight * 0.0
                    index.append(base[k])
                else:
                    weight = weight * (frac[k] if c else 1.0 - frac[k])
                    index.append(base[k] + c)
            out += weight[:, None] * values[np.ravel_multi_index(tuple(index), self.grid_size)]
        return out

    @cached_property
    def grid_values(self) -> FloatArray:
        """(G, K) Nadaraya–Watson estimate at every grid node, flat C-order.

        Computed from the occupied nodes with weights normalised by their
        largest value (no 0/0 far from the data); :meth:`predict`
        interpolates these values multilinearly.
        """
        axes = _axes(self.lower, self.upper, self.grid_size)
        mesh = np.meshgrid(*axes, indexing="ij")
        grid_x = np.stack([m.ravel() for m in mesh], axis=1)
        node_x = self.node_positions()
        sums = self.means * self.counts[:, None]
        u = (grid_x[:, None, :] - node_x[None, :, :]) / self.bandwidth
        logw = -0.5 * np.sum(u * u, axis=2)
        logw -= logw.max(axis=1, keepdims=True)
        w = np.exp(logw)
        return (w @ sums) / (w @ self.counts)[:, None]

    def to_dict(self, decimals: int = 6) -> dict[str, Any]:
        """JSON-serialisable dictionary (outputs rounded to ``decimals``: 1 µm for metres)."""
        return {
            "format": FORMAT,
            "lower": [float(v) for v in self.lower],
            "upper": [float(v) for v in self.upper],
            "grid_size": [int(v) for v in self.grid_size],
            "bandwidth": [float(v) for v in self.bandwidth],
            "nodes": [int(v) for v in self.nodes],
            "counts": [int(round(v)) for v in self.counts],
            "means": np.round(self.means, decimals).tolist(),
            "cv_rms": float(self.cv_rms),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> KernelRegression:
        """Inverse of :meth:`to_dict`.

        Raises:
            InputError: when the dictionary is not a kernel-regression record.
        """
        if data.get("format") != FORMAT:
            raise InputError(
                f"not a kernel regression record (format {data.get('format')!r}, expected "
                f"{FORMAT!r}); write it with KernelRegression.to_dict()"
            )
        try:
            grid = tuple(int(v) for v in data["grid_size"])
            nodes = np.asarray(data["nodes"], dtype=np.int64)
            counts = np.asarray(data["counts"], dtype=float)
            means = np.asarray(data["means"], dtype=float).reshape(len(nodes), -1)
            reg = cls(
                lower=np.asarray(data["lower"], dtype=float),
                upper=np.asarray(data["upper"], dtype=float),
                grid_size=grid,
                bandwidth=np.asarray(data["bandwidth"], dtype=float),
                nodes=nodes,
                counts=counts,
                means=means,
                cv_rms=float(data["cv_rms"]),
            )
        except (KeyError, TypeError, ValueError) as e:
            raise InputError(
                f"malformed kernel regression record ({e}); write it with KernelRegression.to_dict()"
            ) from e
        d = len(grid)
        if not (reg.lower.shape == reg.upper.shape == reg.bandwidth.shape == (d,)) or (
            counts.shape != nodes.shape or len(nodes) == 0
        ):
            raise InputError(
                "inconsistent kernel regression record: lower/upper/bandwidth need one value "
                "per grid axis and nodes/counts/means one entry per occupied node"
            )
        return reg


def _inputs(name: str, x: ArrayLike, n_inputs: int | None) -> FloatArray:
    """Return inputs as (N, D) floats, or raise."""
    a = np.asarray(x, dtype=float)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or (n_inputs is not None and a.shape[1] != n_inputs):
        want = f"(N, {n_inputs})" if n_inputs is not None else "(N, D)"
        raise ShapeError(f"{name} must have shape {want}, one column per input, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} contains NaN or infinite values; fill or cut the gaps first")
    return a


def _axes(lower: FloatArray, upper: FloatArray, grid_size: tuple[int, ...]) -> list[FloatArray]:
    """Node coordinates of each grid axis."""
    return [np.linspace(lower[d], upper[d], grid_size[d]) for d in range(len(grid_size))]


def _smooth(grid: FloatArray, kernels: list[FloatArray]) -> FloatArray:
    """Apply the separable kernel matrices along the first D axes of ``grid``."""
    out = grid
    for d, k in enumerate(kernels):
        out = np.moveaxis(np.tensordot(k, out, axes=([1], [d])), 0, d)
    return out


def _kernel_matrix(axis: FloatArray, h: float) -> FloatArray:
    """Gaussian kernel between the nodes of one axis, (G, G)."""
    u = (axis[:, None] - axis[None, :]) / h
    return np.exp(-0.5 * u * u)


def fit_kernel_regression(
    x: ArrayLike, y: ArrayLike, params: KernelRegressionParams | None = None
) -> KernelRegression:
    """Fit a Nadaraya–Watson regression ``y ≈ f(x)`` (M2 with D = 1, M3 with D = 2).

    Args:
        x: (N, D) training inputs, D in {1, 2} (or (N,) for one input), e.g.
            joint angles in rad.
        y: (N, K) training outputs, e.g. reference S2J components in m.
        params: grid and bandwidth settings; defaults to
            :class:`KernelRegressionParams`.

    Returns:
        The fitted regression.

    Raises:
        ShapeError: on wrong shapes or mismatched numbers of samples.
        InputError: on NaN values, too few samples, more than two inputs or a
            non-positive fixed bandwidth.
    """
    p = params if params is not None else KernelRegressionParams()
    xa = _inputs("x", x, None)
    ya = np.asarray(y, dtype=float)
    if ya.ndim == 1:
        ya = ya[:, None]
    if ya.ndim != 2 or ya.shape[0] != xa.shape[0]:
        raise ShapeError(f"y must have shape (N, K) with the N = {xa.shape[0]} samples of x, got {ya.shape}")
    if not np.all(np.isfinite(ya)):
        raise InputError("y contains NaN or infinite values; fill or cut the gaps first")
    n, d = xa.shape
    if d not in (1, 2):
        raise InputError(f"kernel regression takes one or two inputs, got {d}")
    if n < p.min_samples:
        raise InputError(
            f"kernel regression needs at least {p.min_samples} training samples, got {n}; "
            f"record a longer training trial"
        )
    size = p.grid_size if p.grid_size is not None else (61 if d == 1 else 31)
    if size < 2:
        raise InputError(f"grid_size must be at least 2, got {size}")
    lower = xa.min(axis=0)
    upper = xa.max(axis=0)
    spread = upper - lower
    grid_size = tuple(int(size) if spread[k] > 1e-9 else 1 for k in range(d))

    # nearest-node binning
    idx = []
    for k in range(d):
        if grid_size[k] == 1:
            idx.append(np.zeros(n, dtype=np.int64))
        else:
            u = (xa[:, k] - lower[k]) / spread[k] * (grid_size[k] - 1)
            idx.append(np.clip(np.rint(u).astype(np.int64), 0, grid_size[k] - 1))
    flat = np.ravel_multi_index(tuple(idx), grid_size)
    n_nodes = int(np.prod(grid_size))
    counts = np.bincount(flat, minlength=n_nodes).astype(float)
    sums = np.stack([np.bincount(flat, ya[:, j], n_nodes).astype(float) for j in range(ya.shape[1])], axis=1)
    sq = np.bincount(flat, np.sum(ya * ya, axis=1), n_nodes).astype(float)

    axes = _axes(lower, upper, grid_size)
    if p.bandwidth is not None:
        h = np.asarray(p.bandwidth, dtype=float).reshape(-1)
        if h.shape != (d,) or not np.all(h > 0):
            raise InputError(f"bandwidth must hold {d} positive value(s), one per input, got {p.bandwidth}")
        best_h, best_err = h, _cv_error(axes, h, counts, sums, sq, grid_size)
    else:
        cands = []
        for k in range(d):
            if grid_size[k] == 1:
                cands.append(np.array([1.0]))
            else:
                spacing = spread[k] / (grid_size[k] - 1)
                cands.append(np.geomspace(spacing, 0.5 * spread[k], p.n_bandwidths))
        mesh = np.meshgrid(*cands, indexing="ij")
        best_err, best_h = np.inf, np.ones(d)
        for h_tuple in zip(*(m.ravel() for m in mesh), strict=True):
            h = np.asarray(h_tuple, dtype=float)
            err = _cv_error(axes, h, counts, sums, sq, grid_size)
            if err < best_err:
                best_err, best_h = err, h
    occupied = np.flatnonzero(counts > 0)
    return KernelRegression(
        lower=lower,
        upper=upper,
        grid_size=grid_size,
        bandwidth=best_h,
        nodes=occupied.astype(np.int64),
        counts=counts[occupied],
        means=sums[occupied] / counts[occupied, None],
        cv_rms=float(np.sqrt(best_err / (n * ya.shape[1]))),
    )


def _cv_error(
    axes: list[FloatArray],
    h: FloatArray,
    counts: FloatArray,
    sums: FloatArray,
    sq: FloatArray,
    grid_size: tuple[int, ...],
) -> float:
    """Leave-one-node-out squared error summed over samples and outputs."""
    kernels = [_kernel_matrix(axes[k], float(h[k])) for k in range(len(axes))]
    shape = tuple(grid_size)
    c = counts.reshape(shape)
    s = sums.reshape(shape + (sums.shape[1],))
    num = _smooth(s, kernels).reshape(sums.shape) - sums  # K(0) = 1
    den = _smooth(c, kernels).reshape(counts.shape) - counts
    occ = counts > 0
    total = counts.sum()
    mean = sums.sum(axis=0) / total
    ok = den > 1e-9 * total
    pred = np.where(ok[:, None], num / np.where(ok, den, 1.0)[:, None], mean[None, :])
    err = sq - 2.0 * np.sum(pred * sums, axis=1) + counts * np.sum(pred * pred, axis=1)
    return float(np.sum(err[occ]))

"""Fuzzy-tuned fusion gain of the FTECF (Zhu & Xu 2018 §2.6, eq. 21, Table 1, Fig. 6).

Input ``e1 = ξ / (ξ + ‖q̇_gyr‖)`` (eq. 21) is near 1 when the sensor is still
and near 0 when it turns fast. Two Mamdani rules (Table 1): *e1 small → gain
small*, *e1 large → gain large*; Z- and S-shaped memberships (MATLAB
``zmf``/``smf``); min implication, max aggregation, mean-of-maximum
defuzzification.

Choices the paper leaves open (Fig. 6 gives no numbers):

* The rule output is the complementary-filter gain ``K`` (1/s) rather than
  the fusion factor μ itself; μ follows from eq. 11,
  ``μ = KΔt / (1 + KΔt)``, so one parameter set serves every sampling rate.
* Input memberships ``small = zmf(e1; e_a, e_b)``, ``large = smf(e1; e_a, e_b)``;
  output universe ``[0, k_max]`` with ``small = zmf(K; k_a, k_max)``,
  ``large = smf(K; k_a, k_max)``. Mean of maximum over the continuous universe
  is then exact: with rule strengths ``α_s > α_l`` the maximum set is
  ``[0, zmf⁻¹(α_s)]``, with ``α_l > α_s`` it is ``[smf⁻¹(α_l), k_max]``; the
  gain runs from ``k_a / 2`` (fast motion) to ``k_max`` (still).
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def zmf(x: float, a: float, b: float) -> float:
    """Z-shaped membership (MATLAB ``zmf``): 1 below ``a``, 0 above ``b``, two quadratic arcs between."""
    if x <= a:
        return 1.0
    if x >= b:
        return 0.0
    m = 0.5 * (a + b)
    if x <= m:
        t = (x - a) / (b - a)
        return 1.0 - 2.0 * t * t
    t = (x - b) / (b - a)
    return 2.0 * t * t


@njit(cache=True, inline="always")
def _zmf_upper(alpha: float, a: float, b: float) -> float:
    """Largest ``x`` with ``zmf(x; a, b) >= alpha``, for 0 < alpha <= 1."""
    if alpha >= 0.5:
        return a + (b - a) * math.sqrt(0.5 * (1.0 - alpha))
    return b - (b - a) * math.sqrt(0.5 * alpha)


@njit(cache=True, inline="always")
def _smf_lower(alpha: float, a: float, b: float) -> float:
    """Smallest ``x`` with ``smf(x; a, b) = 1 − zmf(x; a, b) >= alpha``, for 0 < alpha <= 1."""
    return _zmf_upper(1.0 - alpha, a, b) if alpha < 1.0 else b


@njit(cache=True)
def fuzzy_gain(e1: float, e_a: float, e_b: float, k_a: float, k_max: float) -> float:
    """Complementary-filter gain ``K`` (1/s) from the fuzzy input ``e1`` (eq. 21).

    Args:
        e1: Fuzzy input in [0, 1].
        e_a: Input breakpoint where "small" starts to fall.
        e_b: Input breakpoint where "large" reaches 1 (``e_b > e_a``).
        k_a: Output breakpoint where "small" starts to fall, 1/s.
        k_max: End of the output universe, where "large" reaches 1, 1/s
            (``k_max > k_a``).

    Returns:
        The mean of maximum of the aggregated output set, 1/s.
    """
    a_small = zmf(e1, e_a, e_b)
    a_large = 1.0 - a_small
    if a_small > a_large:
        return 0.5 * _zmf_upper(a_small, k_a, k_max)
    if a_large > a_small:
        return 0.5 * (_smf_lower(a_large, k_a, k_max) + k_max)
    # equal strengths (0.5 each): the maximum set is [0, m] ∪ [m, k_max], m the crossover
    return 0.5 * k_max

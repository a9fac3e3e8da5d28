r"""The classic output-error approach (what most updating tools do), as a baseline.

Residuals: relative frequency errors :math:`f_j(q)/f_{t,j} - 1` of the paired modes and the
differences of unit-norm, sign-aligned shapes at the sensors, plus the same strain-energy
weighted regularisation rows as the equation error.  The Jacobian comes from
eigen-sensitivities: :math:`∂λ_j/∂q_k = φ_j^T (∂K/∂q_k) φ_j` and Fox–Kapoor shape
sensitivities truncated to the computed modes,
:math:`∂φ_j/∂q_k = \sum_{r\ne j} φ_r\, φ_r^T(∂K/∂q_k)φ_j / (λ_j - λ_r)`.
Solved with :func:`scipy.optimize.least_squares` (trust region reflective) with lower bounds
on stiffness-like parameters.  Every iteration needs an eigen solve, which is why it is slow.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
from scipy.optimize import least_squares

from .assembly import Discretisation
from .correlation import DEFAULT_SHAPE_NOISE, mac, pair_modes
from .errors import GfeSolverError
from .measured import MeasuredModes
from .modal import discretisation_modes
from .model import Model
from .parameterisation import Parameterisation
from .updating import UpdateResult, _finish, _prepare, _setup


def update_output_error(model: Model | Discretisation, measured: MeasuredModes, *,
                        parameterisation: str | Parameterisation = "nodal",
                        noise: float = DEFAULT_SHAPE_NOISE,
                        regularisation: float = 1e-4, margin: float = 1e-3,
                        extra_modes: int = 12, max_nfev: int = 200) -> UpdateResult:
    """Output-error update of the same parameters (see module docstring).

    ``regularisation`` weighs the same rows as the equation error's, against residuals that
    are relative frequency and shape errors (hence a smaller default)."""
    disc, par, regularisation = _setup(model, parameterisation, regularisation, False)
    start = time.perf_counter()
    pb = _prepare(disc, par, measured, noise, regularisation, margin, None)
    free = disc.free
    n_model = min(measured.n_modes + extra_modes, free.size - 2)
    C = pb.C
    y = pb.y * np.sign(np.sum(pb.y * (C @ pb.phi0), axis=0))
    z0 = pb.q0 / pb.scale
    reg = np.sqrt(regularisation / pb.q0.size * pb.param_weights)
    modes0 = discretisation_modes(disc, n_model)
    pairs = pair_modes(mac(measured.shapes, C @ modes0.shapes[free]))
    t_idx = np.array([t for t, _ in pairs])
    m_idx = np.array([m for _, m in pairs])
    counter = {"eig": 0}

    def evaluate(z):
        q = pb.scale * z
        modes = discretisation_modes(disc, n_model, params=par.element_parameters(q))
        counter["eig"] += 1
        return modes.frequencies_hz, modes.shapes[free]

    def residual_and_jacobian(z):
        freqs, phi = evaluate(z)
        lam = (2 * np.pi * freqs) ** 2
        res, jac = [], []
        for t, m in zip(t_idx, m_idx):
            G = (pb.kmap.jacobian_times(phi[:, m]) @ sp.diags(pb.scale)).toarray()  # ∂(Kφ)/∂z
            dlam = phi[:, m] @ G
            res.append([freqs[m] / measured.frequencies_hz[t] - 1.0])
            jac.append(((freqs[m] / measured.frequencies_hz[t]) * dlam / (2 * lam[m]))[None, :])
            others = np.array([r for r in range(len(lam)) if r != m])
            coupling = (phi[:, others].T @ G) / (lam[m] - lam[others])[:, None]
            dphi = phi[:, others] @ coupling
            c = C @ phi[:, m]
            norm = np.linalg.norm(c)
            sign = np.sign(c @ y[:, t]) or 1.0
            chat = c / norm
            res.append(sign * chat - y[:, t])
            jac.append(sign * (np.eye(c.size) - np.outer(chat, chat)) @ (C @ dphi) / norm)
        res.append(reg * (z - z0))
        jac.append(np.diag(reg))
        return np.concatenate(res), np.vstack(jac)

    cache = {"z": None}

    def fun(z):
        cache["r"], cache["J"] = residual_and_jacobian(z)
        cache["z"] = z.copy()
        return cache["r"]

    def jac(z):
        if cache["z"] is None or not np.array_equal(cache["z"], z):
            fun(z)
        return cache["J"]

    lower = np.full(z0.size, -np.inf)
    stiff = np.array([not lab.startswith(("dk/dx", "k_wt")) for lab in par.labels])
    lower[stiff] = margin * pb.k0 / pb.scale[stiff]
    x0 = np.maximum(z0, lower + 1e-12)
    try:
        sol = least_squares(fun, x0, jac=jac, bounds=(lower, np.inf), method="trf",
                            max_nfev=max_nfev, x_scale="jac")
    except GfeSolverError as exc:
        # no positivity constraints here: an iterate can make an element indefinite
        stats = {"return_status": str(exc), "iter_count": counter["eig"],
                 "eigen_solves": counter["eig"]}
        return _finish(pb, "expand", "output-error", pb.scale * cache["z"], pb.phi0,
                       "indefinite model reached", False, stats,
                       time.perf_counter() - start, [f"stopped: {exc}"])
    stats = {"return_status": sol.message, "iter_count": int(sol.nfev),
             "eigen_solves": counter["eig"], "cost": float(sol.cost)}
    return _finish(pb, "expand", "output-error", pb.scale * sol.x, pb.phi0,
                   "converged" if sol.status > 0 else sol.message, bool(sol.status > 0),
                   stats, time.perf_counter() - start, [])

r"""Equation-error updating of generic stiffness parameters (CasADi + IPOPT; cvxpy SDP check).

Objective (the paper's strain-energy-weighted equation error, made precise)
----------------------------------------------------------------------------
For measured modes j with circular frequency :math:`ω_j` and a full shape :math:`φ_j`
(free DOFs), the equation error is :math:`r_j(q) = (K(q) - ω_j^2 M) φ_j`, affine in the
parameter vector q of a :class:`~gfe_opt.parameterisation.Parameterisation`.  We minimise

.. math:: J(q) = \frac{1}{n_r J_0}\sum_j \| W_j r_j \|^2
          + \frac{μ}{n_q} \sum_k v_k \Big(\frac{q_k - q_{0,k}}{s_k}\Big)^2

with the row weighting :math:`W_j = \mathrm{diag}(\sqrt{ε + \hat e_{ij}})\, D / F_j`:

* :math:`D = \mathrm{diag}(M)^{-1/2}` puts force and moment rows on one scale;
* :math:`F_j = \|ω_j^2 D M φ_j\|` makes every mode count equally, whatever its scale;
* :math:`J_0` is the mean squared weighted error of the initial model, so J starts at 1;
* :math:`\hat e_{ij}` is the strain energy of mode j (initial model) in the elements next to
  node i, divided by its mean over the nodes, and ε = 0.05: equations where the mode stores
  strain energy carry the stiffness information and count most, those where it stores none
  are mostly noise.

The regularisation (μ, default :func:`default_regularisation`) holds parameters towards the
initial model with weights :math:`v_k = 1/(ε + \hat e_k)`, :math:`\hat e_k` the normalised
strain energy of the elements the parameter acts on: parameters that do not contribute to the
strain energy of the measured modes (the paper's concern) do not wander.  :math:`s_k` is the
parameter's scale.

Incomplete measurements
-----------------------
Measured shapes are translations at sensors.  Two treatments:

* ``"expand"`` (default): shapes are expanded with the model
  (:func:`~gfe_opt.correlation.expand_modes`, regularised by the shape noise δ); J is then a
  convex quadratic in q, the form the cvxpy SDP cross-check (:func:`update_sdp`) solves too.
  The expansion is then repeated with the *updated* model and the convex problem re-solved
  (``refinements``, default 2): a block-coordinate treatment of the bilinear problem.
  Default because each step is convex and robust: on the case study (0.5 % noise) each IPOPT
  solve takes about 20 iterations and the crack is located.
* ``"bilinear"``: the free-DOF shapes :math:`φ_j` are decision variables next to q, with
  the data term :math:`\frac{1}{δ^2 n_s m}\sum_j \|Cφ_j - y_j\|^2` (y_j scaled to unit
  norm), started from the ``expand`` solution, so unmeasured DOFs are estimated with the
  *updated* model.  Measured weakness: on the noisy case study IPOPT often stops at its
  iteration limit; the result then says so (``ok`` False) and is not to be used.

Modal energy balance (explicit equality, linear in q): for the shapes used,
:math:`φ_j^T K(q) φ_j = ω_j^2 φ_j^T M φ_j`, so the updated model's Rayleigh quotient at each
measured shape is the measured eigenvalue.  Without it the equation error alone can be made
small by an over-softened zone whose first frequency is 20-65 % low (measured on the case
study); with it and two refinements the updated first frequency is within 0.01 %.

Solving the convex step
-----------------------
Each ``expand`` step minimises a convex quadratic under the linear energy-balance equalities
and the convex element conditions below.  ``solver="auto"`` (default) first solves it without
the inequalities by one sparse factorisation of its symmetric quasi-definite KKT system
(residuals lifted as unknowns, so BᵀB is never formed; the few energy-balance rows by a Schur
complement; iterative refinement to a relative residual below 1e-8).  If every element
condition holds strictly there, that point is the optimum of the constrained problem (a convex
problem whose inequality multipliers are all zero), and the step is reported as
``Solved_Direct_KKT``.  Otherwise the step is the small problem of the parameters that the
elements it breaks read (:func:`_solve_reduced`): with those held, the rest of the step is an
equality problem on the same factorisation, affine in them, so the step reduces to a
quadratic in a few parameters under the conditions of the elements they move, a
second-order cone program that Clarabel solves, IPOPT where Clarabel does not (whitened,
the conditions held 1e-9 above the margin; :func:`_conic_reduced`, :func:`_ipopt_reduced`;
on the semi-rigid portal's realisation 10x faster than IPOPT alone, which took up to 500
iterations there and stopped at that limit on some); elements still broken, and
elements whose condition binds there but which read a parameter outside it, free their
parameters too, until neither is left (then the small problem's optimality conditions are
the step's).  Measured: a 2000-element draw of the realisation whose two refinements broke
13 and 16 elements near a pinned end, 11.3 s → 2.7 s; on the 20-element dip of
tests/test_updating.py the point agrees with a conic solver's (Clarabel) to 7e-9 of the
largest parameter, IPOPT's on the whole step to 2.4e-7 (IPOPT relaxes its bounds by 1e-8);
on a 40-element bar held at 0.99 of its rigidity the same 7 elements bind as in a QP's
solution, the objective within 1.1e-7 and the parameters within 1.5e-5 (a direction of the
step 5e-9 as curved as its stiffest), whichever solves the small problem.  IPOPT solves
the whole step when the reduction fails (more than :data:`REDUCED_SIZE` parameters or
:data:`REDUCED_ROUNDS` rounds, uniform mass parameters, a singular border).
``solver="ipopt"`` calls IPOPT for every step, lifted too: residual variables u with
``u = B z + b`` (or ``L u = B z + b``, Q = L Lᵀ by a banded Cholesky factorisation, for the
energy weighting) and objective uᵀu; the unlifted ``||B z + b||²`` stalled at "acceptable"
on fine meshes.
Measured (scripts/bench.py, N = 2000): the direct step is about 10x faster than IPOPT's; both
give the same parameters to 1e-8 where no constraint is active (tests/test_updating.py).

Weighting of the residual (``weighting``)
-----------------------------------------
``"rows"`` (default) is W above.  ``"energy"`` measures each mode's residual force in the
flexibility of the initial model instead, :math:`\hat r_j^T \tilde K^{-1} \hat r_j` with
:math:`\tilde K = K_0 + σ M` (σ = 0.01 ω_min², positive definite also for free structures)
and :math:`\hat r_j = r_j / F_j`, :math:`F_j^2 = f_j^T \tilde K^{-1} f_j`, :math:`f_j = ω_j^2
M φ_j`: the strain energy of the static deflection the residual forces would cause.  Errors
δφ in the shapes enter the row residual amplified by :math:`(N / jπ)^4` (1e14 for mode 1 at
N = 10,000: double-precision rounding of the shapes already hides a 30 % taper); in the
flexibility metric they are not amplified.  Measured: N = 10,000, 30 % taper, 5 modes
(scripts/bench.py) and a 50 % taper (tests/test_updating.py): row weighting leaves 15-24 %
error over the middle 90 % of the span, energy weighting 0.6-2 %.  Near a pinned end the
bending moment vanishes, k_i is barely determined and the regularisation holds it at the
initial value (both weightings; over a longer stretch with ``"energy"``).

Constraints (IPOPT, explicit): for every element :math:`k_{ww} \ge m k_0`,
:math:`k_{θθ} \ge m k_0`, :math:`k_{ww}k_{θθ} - k_{wθ}^2 \ge m k_0^2` (bar: :math:`k \ge m
k_0`), m the margin (1e-3) and k_0 the initial mean EI (EA).  Inter-element equilibrium is
built into the ``nodal``, ``linear`` and ``constant`` parameterisations (eq. 13); the
``element`` parameterisation has none, as in eq. 11.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import casadi as ca
import numpy as np
import scipy.sparse as sp
from scipy.linalg import cho_solve_banded, cholesky_banded
from scipy.sparse.linalg import splu, spsolve_triangular

from . import elements as el
from .assembly import Discretisation, discretise
from .correlation import DEFAULT_SHAPE_NOISE, discrepancy_factor, expand_modes
from .errors import GfeInputError, GfeSolverError
from .measured import MeasuredModes, observation, sensor_matrix
from .model import Model
from .parameterisation import Parameterisation, parameterisation_for
from .threads import one_blas_thread

METHODS = ("expand", "bilinear")
SOLVERS = ("auto", "ipopt")
WEIGHTINGS = ("auto", "rows", "energy")
#: weighting="auto": rows (the paper's W) up to this many elements, energy above.  Measured
#: (30 % taper, 5 modes, exact shapes at every node; error over the middle 90 % of the span):
#: rows 0.5 % up to 1500 elements, 0.9 % at 2000, 3.8 % at 2500, 7 % at 3000, 15-24 % at
#: 10 000; energy 0.4 % at every size but 23 % within 5 % of a pinned end (held near the
#: initial value there), where rows stays within 1-2 % up to 1500 elements
AUTO_ENERGY_ELEMENTS = 1500
ENERGY_FLOOR = 0.05
#: weighting="energy": σ = ENERGY_SHIFT ω_min² in K̃ = K_0 + σM (positive definite when free)
ENERGY_SHIFT = 0.01


def default_regularisation(all_dofs_measured: bool) -> float:
    """μ = 0.01 when every DOF was measured (a well-determined problem), μ = 1 when shapes
    are expanded from translations (unmeasured DOFs come from a model, many parameters are
    weakly determined).  Measured (scripts/paper_case_study.py, tests/test_updating.py): with
    μ = 1 the case-study crack is located on 23, 46 and 92 elements with the first frequency
    within 0.6 % and changes far from the crack below 3.5 %; with μ = 0.1 they reach 21 %.
    With all DOFs of a taper measured, μ = 0.01 recovers k_i within 1 %, μ = 1 within 5 %."""
    return 0.01 if all_dofs_measured else 1.0


# -------------------------------------------------------------------------------------------
# Problem data
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StiffnessMap:
    """K_ff(q) on the free DOFs: nonzeros = ``S @ q + extra`` on a fixed CSC ``pattern``."""

    pattern: sp.csc_matrix
    S: sp.csr_matrix
    extra: np.ndarray

    def matrix(self, q) -> sp.csc_matrix:
        K = self.pattern.copy()
        K.data = self.S @ np.asarray(q, float) + self.extra
        return K

    def extra_matrix(self) -> sp.csc_matrix:
        """The parameter-independent part of K_ff (geometric, foundation, springs)."""
        K = self.pattern.copy()
        K.data = self.extra.copy()
        return K

    def jacobian_times(self, phi) -> sp.csr_matrix:
        """G with K_ff(q) φ = G q + K_extra φ for a fixed vector φ (free DOFs)."""
        cols_of_nz = np.repeat(np.arange(self.pattern.shape[1]), np.diff(self.pattern.indptr))
        row_of_nz = self.pattern.indices
        R = sp.csr_matrix((phi[cols_of_nz], (row_of_nz, np.arange(self.pattern.nnz))),
                          shape=(self.pattern.shape[0], self.pattern.nnz))
        return (R @ self.S).tocsr()


def stiffness_map(disc: Discretisation, par: Parameterisation) -> StiffnessMap:
    """Linear map from parameters q to the nonzeros of the free-DOF stiffness."""
    free = disc.free
    n_dof = disc.n_dof
    local = -np.ones(n_dof, dtype=int)
    local[free] = np.arange(free.size)
    dofs = disc.element_dofs()
    n_el, size = dofs.shape
    keys = par.keys
    unit = {}
    for key in keys:
        unit[key] = disc.stiffness_elements(
            {k: np.full(n_el, 1.0 if k == key else 0.0) for k in keys})
    rows = np.repeat(dofs, size, axis=1).ravel()
    cols = np.tile(dofs, (1, size)).ravel()
    keep = (local[rows] >= 0) & (local[cols] >= 0)
    r, c = local[rows[keep]], local[cols[keep]]
    ke = sp.csc_matrix(disc.fixed_stiffness())[free][:, free].tocoo()
    n = free.size
    pattern = sp.csc_matrix((np.ones(r.size + ke.nnz), (np.concatenate([r, ke.row]),
                                                         np.concatenate([c, ke.col]))),
                            shape=(n, n))
    pattern.sort_indices()
    key_of = np.repeat(np.arange(n), np.diff(pattern.indptr)) * n + pattern.indices  # col*n+row

    def nz_index(rr, cc):
        return np.searchsorted(key_of, cc * n + rr)

    nz = nz_index(r, c)
    element = np.repeat(np.arange(n_el), size * size)[keep]
    S_rows, S_cols, S_vals = [], [], []
    for i, key in enumerate(keys):
        S_rows.append(nz)
        S_cols.append(i * n_el + element)
        S_vals.append(unit[key].ravel()[keep])
    S_p = sp.csr_matrix((np.concatenate(S_vals), (np.concatenate(S_rows),
                                                  np.concatenate(S_cols))),
                        shape=(pattern.nnz, len(keys) * n_el))
    extra = np.zeros(pattern.nnz)
    np.add.at(extra, nz_index(ke.row, ke.col), ke.data)
    return StiffnessMap(pattern=pattern, S=(S_p @ par.matrix).tocsr(), extra=extra)


MASS_NAMES = {"beam": ("m11", "m12", "m14", "m22"), "bar": ("beta",)}
MASS_MARGIN = 1e-6


@dataclass(frozen=True)
class MassMap:
    """Uniform generic mass parameters (eq. 17 m11, m12, m14, m22; bar eq. 2 β):
    M_ff(m) = ``rest + Σ_b m_b basis[b]`` and element matrices likewise."""

    names: tuple
    m0: np.ndarray
    basis: tuple           # free-DOF global matrices ∂M/∂m_b
    rest: sp.csc_matrix    # M_ff at m = 0
    element_basis: np.ndarray   # (n_b, n_elements, n, n) physical
    element_rest: np.ndarray    # (n_elements, n, n)

    def matrix(self, m) -> sp.csc_matrix:
        out = self.rest.copy()
        for value, b in zip(m, self.basis):
            out = out + value * b
        return out.tocsc()

    def elements(self, m) -> np.ndarray:
        return self.element_rest + np.tensordot(np.asarray(m, float), self.element_basis, 1)

    def conditions(self, m) -> list:
        """Feasibility values (each must exceed MASS_MARGIN), numpy or CasADi."""
        if self.names == ("beta",):
            return [0.25 - m[0]]
        p = dict(zip(self.names, (m[i] for i in range(4))))
        return [c.value(p) for c in el.SYMMETRIC_BEAM_MASS_CONDITIONS]


def mass_map(disc: Discretisation) -> MassMap:
    """The mass of ``disc`` as a uniform generic family around its present parameters."""
    L = disc.element_length
    if disc.kind == "bar":
        t = np.array([1.0, 1.0])
        scaled_basis = [el.BAR_MASS_BASIS["beta"]]
        tt = np.ones((2, 2))
    else:
        t = np.array([1.0, 0.0, 1.0, 0.0])
        scaled_basis = [el.SYMMETRIC_BEAM_MASS_BASIS[k] for k in MASS_NAMES["beam"]]
        scale = el.beam_dof_scaling(L)
        tt = np.outer(scale, scale)
    total = np.einsum("i,eij,j->e", t, disc.mass, t)  # ρ A L of each element
    element_basis = np.array([total[:, None, None] * (b * tt) for b in scaled_basis])
    # present parameters: least squares of the element matrices on the basis (mean element)
    design = element_basis.reshape(len(scaled_basis), -1).T
    m0 = np.linalg.lstsq(design, disc.mass.ravel() - _constant_part(disc, total, tt),
                         rcond=None)[0]
    element_rest = disc.mass - np.tensordot(m0, element_basis, 1)
    free = disc.free

    def global_free(elements):
        return sp.csc_matrix(disc.assemble_elements(elements))[free][:, free]

    return MassMap(names=MASS_NAMES[disc.kind], m0=m0,
                   basis=tuple(global_free(b) for b in element_basis),
                   rest=global_free(element_rest), element_basis=element_basis,
                   element_rest=element_rest)


def _constant_part(disc, total, tt):
    constant = el.BAR_MASS_CONSTANT if disc.kind == "bar" else el.SYMMETRIC_BEAM_MASS_CONSTANT
    return (total[:, None, None] * (constant * tt)).ravel()


@dataclass
class UpdateResult:
    """Outcome of an equation-error update.  ``ok`` is False for any failed or unphysical solve."""

    parameterisation: Parameterisation
    method: str
    solver: str
    q: np.ndarray
    q0: np.ndarray
    element_parameters: dict
    discretisation: Discretisation
    objective: float
    objective_initial: float
    residual_per_mode: np.ndarray
    residual_per_mode_initial: np.ndarray
    status: str
    success: bool
    stats: dict
    violations: list
    seconds: float
    shapes: np.ndarray | None = None
    notes: list = field(default_factory=list)
    scale: np.ndarray | None = None
    mass_parameters: dict | None = None
    mass_parameters_initial: dict | None = None
    k0: float = 1.0
    margin: float = 0.0

    @property
    def ok(self) -> bool:
        return self.success and not self.violations

    def relative_change(self) -> np.ndarray:
        """(q - q0) / scale of each parameter (k_i relative to k0; slopes to k0 / L)."""
        return (self.q - self.q0) / self.scale

    def summary(self) -> str:
        state = "ok" if self.ok else "FAILED"
        lines = [f"{self.solver} ({self.method}, {self.parameterisation.name}): {state}, "
                 f"status {self.status}, objective {self.objective_initial:.3e} -> "
                 f"{self.objective:.3e} in {self.seconds:.2f} s"]
        lines += [f"  violation: {v}" for v in self.violations]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


@dataclass(frozen=True)
class Flexibility:
    """Q = K̃ = K_0 + σM on the free DOFs (``weighting="energy"``), factored once as Q = L Lᵀ
    (banded Cholesky; the DOFs are numbered node by node, so Q is banded)."""

    Q: sp.csc_matrix
    factor: np.ndarray  # lower banded form of L (scipy.linalg.cholesky_banded)

    @classmethod
    def of(cls, Q) -> Flexibility:
        Q = sp.csc_matrix(Q)
        coo = sp.tril(Q).tocoo()
        band = int(np.max(coo.row - coo.col)) + 1
        ab = np.zeros((band, Q.shape[0]))
        ab[coo.row - coo.col, coo.col] = coo.data
        return cls(Q=Q, factor=cholesky_banded(ab, lower=True))

    def solve(self, b) -> np.ndarray:
        """Q⁻¹ b."""
        return cho_solve_banded((self.factor, True), b)

    def lower_blocks(self, n_blocks: int) -> sp.csc_matrix:
        """blockdiag(L, ..., L), one block per mode."""
        n = self.Q.shape[0]
        offsets = np.arange(self.factor.shape[0])
        L = sp.diags([self.factor[k, :n - k] for k in offsets], -offsets, format="csc")
        return sp.block_diag([L] * n_blocks, "csc")


@dataclass
class _Problem:
    disc: Discretisation
    par: Parameterisation
    kmap: StiffnessMap
    M: sp.csc_matrix
    C: sp.csr_matrix
    omega: np.ndarray
    y: np.ndarray
    phi0: np.ndarray
    row_weights: np.ndarray
    q0: np.ndarray
    scale: np.ndarray
    param_weights: np.ndarray
    k0: float
    noise: float
    regularisation: float
    margin: float
    eq_scale: float = 1.0
    mmap: MassMap | None = None
    # weighting="energy": residuals measured as r̂ᵀ K̃⁻¹ r̂ (None: Euclidean, "rows")
    flexibility: Flexibility | None = None
    _jacobians: dict = field(default_factory=dict, repr=False)

    def metric_norms(self, weighted) -> np.ndarray:
        """Per-mode squared norms of weighted residual columns in the problem's metric."""
        if self.flexibility is None:
            return np.sum(weighted**2, axis=0)
        return np.einsum("ij,ij->j", weighted, self.flexibility.solve(weighted))

    # x = [q; m]: stiffness parameters, then (optionally) uniform mass parameters
    @property
    def n_q(self) -> int:
        return self.q0.size

    @property
    def x0(self) -> np.ndarray:
        return self.q0 if self.mmap is None else np.concatenate([self.q0, self.mmap.m0])

    @property
    def x_scale(self) -> np.ndarray:
        extra = 0 if self.mmap is None else len(self.mmap.names)
        return np.concatenate([self.scale, np.full(extra, 0.1)])

    @property
    def x_weights(self) -> np.ndarray:
        extra = 0 if self.mmap is None else len(self.mmap.names)
        return np.concatenate([self.param_weights, np.ones(extra)])

    def mass_matrix(self, x) -> sp.csc_matrix:
        return self.M if self.mmap is None else self.mmap.matrix(x[self.n_q:])

    def mode_jacobian(self, j: int):
        """(A, c) with (K(q) - ω_j² M(m)) φ = A x + c for the problem's shape φ0_j (free
        DOFs), computed once."""
        if j in self._jacobians:
            return self._jacobians[j]
        phi = self.phi0[:, j]
        w2 = self.omega[j] ** 2
        A = self.kmap.jacobian_times(phi)
        c = self.kmap.extra_matrix() @ phi
        if self.mmap is None:
            out = A, c - w2 * (self.M @ phi)
        else:
            H = np.stack([b @ phi for b in self.mmap.basis], axis=1)
            out = (sp.hstack([A, sp.csr_matrix(-w2 * H)]).tocsr(),
                   c - w2 * (self.mmap.rest @ phi))
        self._jacobians[j] = out
        return out


def _node_energy_share(disc: Discretisation, shapes_full) -> np.ndarray:
    """(n_nodes, m): strain energy next to each node, normalised by its mean."""
    e = np.abs(disc.element_strain_energy(shapes_full))
    node = np.zeros((e.shape[0] + 1, e.shape[1]))
    node[:-1] += 0.5 * e
    node[1:] += 0.5 * e
    return node / np.maximum(node.mean(axis=0), 1e-300)


def _prepare(disc, par, measured, noise, regularisation, margin, q0, full_shapes=None,
             expansion_disc=None, update_mass=False, weighting="rows", kmap=None):
    """Problem data; shapes are expanded with ``disc`` or, when given, ``expansion_disc``
    (the current updated model).  ``kmap``: the stiffness map of (disc, par) if known."""
    free = disc.free
    K_full, M_full = disc.global_matrices()
    frame = disc.kind == "frame"
    C_full = observation(disc, measured) if frame else sensor_matrix(
        disc.nodes, disc.kind, measured.x, measured.dof, measured.source)
    y = measured.shapes / np.linalg.norm(measured.shapes, axis=0)
    if full_shapes is None:
        if expansion_disc is None:
            expander, (K_exp, M_exp) = disc, (K_full, M_full)
        else:
            expander, (K_exp, M_exp) = expansion_disc, expansion_disc.global_matrices()
        # a beam's or bar's expansion at the noise norm the stated noise stays below, not
        # its mean: at the mean the update rang on a sixth of noisy copies; a frame's at
        # the mean (its members did not ring there, and the larger τ cost its readings:
        # correlation.discrepancy_factor)
        tau = 1.0 if frame else discrepancy_factor(y.shape[0])
        phi_full = expand_modes(expander, C_full, measured.omega, y, noise * tau, K_exp,
                                M_exp).shapes
    else:
        phi_full = np.asarray(full_shapes, float)
        if phi_full.shape != (disc.n_dof, measured.n_modes):
            raise ValueError(f"full_shapes must have shape {(disc.n_dof, measured.n_modes)}")
    M = sp.csc_matrix(M_full)[free][:, free]
    C = sp.csr_matrix(C_full)[:, free]
    kmap = stiffness_map(disc, par) if kmap is None else kmap
    d = 1.0 / np.sqrt(M.diagonal())
    if frame:
        per_dof = disc.dof_energy_share(phi_full)[free]
    else:
        node_share = _node_energy_share(disc, phi_full)  # (n_nodes, m)
        per_dof = np.repeat(node_share, disc.dofs_per_node, axis=0)[free]
    inertia = measured.omega**2 * (M @ phi_full[free])
    flexibility = None
    if weighting == "energy":
        flexibility = Flexibility.of(sp.csc_matrix(K_full)[free][:, free]
                                     + ENERGY_SHIFT * np.min(measured.omega) ** 2 * M)
        F = np.sqrt(np.einsum("ij,ij->j", inertia, flexibility.solve(inertia)))
        row_weights = np.ones_like(inertia) / F
    else:
        F = np.linalg.norm(d[:, None] * inertia, axis=0)
        row_weights = np.sqrt(ENERGY_FLOOR + per_dof) * d[:, None] / F
    k_scale = disc.stiffness_params["k"] if disc.kind == "bar" else \
        disc.stiffness_params["k_ww"] / 12.0
    k0 = float(np.mean(k_scale))
    if q0 is None:
        q0 = par.fit(disc.stiffness_params)
    labels = par.labels
    scale = disc.parameter_scale(par) if frame else np.array(
        [k0 / disc.element_length if lab.startswith("dk/dx") else k0 for lab in labels])
    if par.name == "element" and disc.kind == "beam":
        scale = scale * np.repeat([12.0, 6.0, 4.0], par.n_elements)
    if frame:   # bending and axial parameters each by their own energy
        share = disc.parameter_energy(par, phi_full)
    else:
        e_el = np.abs(disc.element_strain_energy(phi_full)).sum(axis=1)
        e_el = e_el / max(e_el.mean(), 1e-300)
        share = np.abs(par.matrix).T @ np.tile(e_el, len(par.keys))
    share = share / max(share.mean(), 1e-300)
    param_weights = 1.0 / (ENERGY_FLOOR + share)
    pb = _Problem(disc=disc, par=par, kmap=kmap, M=M, C=C, omega=measured.omega, y=y,
                  phi0=phi_full[free], row_weights=row_weights, q0=np.asarray(q0, float),
                  scale=scale, param_weights=param_weights, k0=k0, noise=noise,
                  regularisation=regularisation, margin=margin,
                  mmap=mass_map(disc) if update_mass else None, flexibility=flexibility)
    K0 = pb.kmap.matrix(pb.q0)
    r0 = row_weights * (K0 @ pb.phi0 - measured.omega**2 * (M @ pb.phi0))
    pb.eq_scale = max(float(np.sum(pb.metric_norms(r0)) / r0.size), 1e-300)
    return pb


def _objective_terms(pb: _Problem, x, phi, data_term: bool):
    """Numeric J and per-mode relative residuals for given x = [q; m] and free-DOF shapes."""
    x = np.asarray(x, float)
    K = pb.kmap.matrix(x[:pb.n_q])
    res = K @ phi - (pb.omega**2) * (pb.mass_matrix(x) @ phi)
    weighted = pb.row_weights * res
    squares = pb.metric_norms(weighted)
    per_mode = np.sqrt(squares)
    J = np.sum(squares) / weighted.size / pb.eq_scale
    dz = (x - pb.x0) / pb.x_scale
    J += pb.regularisation / x.size * np.sum(pb.x_weights * dz**2)
    if data_term:
        mis = pb.C @ phi - pb.y
        J += np.sum(mis**2) / (pb.noise**2 * mis.size)
    return float(J), per_mode


def _feasibility(pb: _Problem, x) -> list:
    conds = el.BAR_CONDITIONS[:1] if pb.disc.kind == "bar" else el.BEAM_STIFFNESS_CONDITIONS
    params = pb.par.element_parameters(x[:pb.n_q])
    scaled = {k: np.asarray(v) / pb.k0 for k, v in params.items()}
    found = el.feasibility_violations(conds, scaled)
    if pb.disc.kind == "frame":   # a frame's members: the bar's k > 0 too
        found += el.feasibility_violations(el.BAR_CONDITIONS[:1], {"k": scaled["k"]})
    if pb.mmap is not None:
        m = x[pb.n_q:]
        conds = el.BAR_CONDITIONS[1:] if pb.disc.kind == "bar" else \
            el.SYMMETRIC_BEAM_MASS_CONDITIONS
        p = dict(zip(pb.mmap.names, m))
        found += el.feasibility_violations(conds, p)
    return found


def _updated_discretisation(pb: _Problem, x) -> Discretisation:
    disc = pb.disc.with_stiffness(pb.par.element_parameters(x[:pb.n_q]))
    if pb.mmap is not None:
        disc = replace(disc, mass=pb.mmap.elements(x[pb.n_q:]))
    return disc


def _finish(pb, method, solver, x, phi, status, success, stats, seconds, notes):
    x = np.asarray(x, float)
    q = x[:pb.n_q]
    params = pb.par.element_parameters(q)
    disc = _updated_discretisation(pb, x)
    data_term = method == "bilinear"
    J, per_mode = _objective_terms(pb, x, phi, data_term)
    J0, per_mode0 = _objective_terms(pb, pb.x0, pb.phi0, data_term)
    violations = _feasibility(pb, x)
    if not success:
        notes = notes + [f"the solver did not converge ({status}); parameters are its last "
                         "iterate and must not be used as an updated model"]
    shapes = np.zeros((pb.disc.n_dof, phi.shape[1]))
    shapes[pb.disc.free] = phi
    return UpdateResult(parameterisation=pb.par, method=method, solver=solver, q=np.asarray(q),
                        q0=pb.q0, element_parameters=params, discretisation=disc, objective=J,
                        objective_initial=J0, residual_per_mode=per_mode,
                        residual_per_mode_initial=per_mode0, status=status, success=success,
                        stats=stats, violations=violations, seconds=seconds, shapes=shapes,
                        notes=notes, scale=pb.scale, k0=pb.k0, margin=pb.margin,
                        mass_parameters=None if pb.mmap is None else
                        dict(zip(pb.mmap.names, x[pb.n_q:].tolist())),
                        mass_parameters_initial=None if pb.mmap is None else
                        dict(zip(pb.mmap.names, pb.mmap.m0.tolist())))


# -------------------------------------------------------------------------------------------
# IPOPT
# -------------------------------------------------------------------------------------------


def _expanded_least_squares(pb: _Problem):
    """The ``expand`` objective as ``||B z + b||² + ||V (z - z0)||²`` in scaled z = x / s."""
    blocks, consts = [], []
    norm = np.sqrt(pb.phi0.size * pb.eq_scale)
    for j in range(pb.omega.size):
        A, c = pb.mode_jacobian(j)
        w = pb.row_weights[:, j] / norm
        # diag(w) A diag(x_scale), on A's entries (two sparse products cost more than it)
        A = sp.csr_matrix(A, copy=True)
        A.data *= np.repeat(w, np.diff(A.indptr))
        A.data *= pb.x_scale[A.indices]
        blocks.append(A)
        consts.append(w * c)
    reg = np.sqrt(pb.regularisation / pb.x0.size * pb.x_weights)
    return sp.vstack(blocks).tocsr(), np.concatenate(consts), reg


def _energy_balance(pb: _Problem):
    """Rows (A, b) of the modal energy balance φ_jᵀ K(q) φ_j = ω_j² φ_jᵀ M(m) φ_j (fixed
    φ_j), divided by the present kinetic term: ``A x + b = 0``, linear in x."""
    rows, rhs = [], []
    for j in range(pb.omega.size):
        phi = pb.phi0[:, j]
        kinetic = pb.omega[j] ** 2 * phi @ (pb.M @ phi)
        A, c = pb.mode_jacobian(j)
        rows.append((A.T @ phi) / kinetic)
        rhs.append((phi @ c) / kinetic)
    return np.array(rows), np.array(rhs)


DIRECT_STATUS = "Solved_Direct_KKT"
#: a step whose direct point broke element conditions: rounds of the reduced problem
#: (:func:`_solve_reduced`), each freeing the parameters of the elements still broken,
#: before the whole step is left to IPOPT.  Eight since the cone programs (stop 79): a round
#: costs milliseconds, and of the 18 reduced steps of the semi-rigid portal's 12 draws
#: (``gfe-opt diagnose``'s realisation) 4 needed a fifth round, the four-round limit sent
#: them whole to IPOPT (1-4 s each), and none needed more than five
REDUCED_ROUNDS = 8
#: the reduced problem's solver: "clarabel" (its cone program, :func:`_conic_reduced`;
#: IPOPT where Clarabel does not solve it) or "ipopt" (:func:`_ipopt_reduced`, as before
#: stop 79; ``scripts/bench.py --parts reduced`` runs both side by side)
REDUCED_SOLVER = "clarabel"
#: at most this many parameters in the reduced problem (a dense one)
REDUCED_SIZE = 200
#: the reduced problem holds its conditions this far above the margin (scaled by k0, k0²):
#: the point is then solved again by the bordered system itself, whose rounding moves a
#: binding condition by up to 1e-11 (measured), and the step's point must satisfy every
#: condition strictly, as a direct one does (IPOPT on the whole step relaxes them by 1e-8)
REDUCED_LIFT = 1e-9
#: a condition of the reduced problem within this of its margin binds (IPOPT's interior
#: point leaves a binding one 1e-10 above its bound, Clarabel's a few 1e-9 where its bound
#: was raised, :func:`_conic_reduced`; a condition counted binding that is not
#: only makes the problem larger)
REDUCED_BINDING = 1e-7


class _Ldl:
    """The LDLᵀ factor of a quasi-definite matrix by QDLDL (approximate minimum-degree
    order, no pivoting), whose order and symbolic analysis the next matrix of the same
    sparsity pattern reuses (``previous``: a generic update's steps, 3 an update; at 2 000
    elements 22.7 ms a factor with SuperLU, 13.6 ms a new one, 4.3 ms a reused one,
    README Speed).  SuperLU (diagonal pivots where they are not zero, in its own
    minimum-degree order) where QDLDL fails or on request (``superlu``: :func:`_solve_direct`
    when the solve from QDLDL's factor stays inaccurate)."""

    def __init__(self, matrix, previous=None, superlu: bool = False):
        import qdldl

        matrix = sp.csc_matrix(matrix)
        matrix.sort_indices()
        self.pattern = (matrix.shape, matrix.indptr.copy(), matrix.indices.copy())
        same = previous is not None and previous.pattern[0] == matrix.shape and \
            np.array_equal(previous.pattern[1], matrix.indptr) and \
            np.array_equal(previous.pattern[2], matrix.indices)
        self.qdldl = self.superlu = None
        if previous is not None and not same:
            previous.qdldl = None   # (released before the new factor is made: memory)
        if not superlu:
            try:
                if same and previous.qdldl is not None:
                    previous.qdldl.update(matrix)
                    self.qdldl, previous.qdldl = previous.qdldl, None
                else:
                    self.qdldl = qdldl.Solver(matrix)
                return
            except (ValueError, RuntimeError):   # a zero pivot
                self.qdldl = None
                if previous is not None:
                    previous.qdldl = None   # (its factor spoilt by the failed update)
        # SuperLU pivots off a zero diagonal (its RuntimeError, an exactly singular matrix:
        # the caller's)
        self.superlu = splu(matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                            options={"SymmetricMode": True})

    def solve(self, b):
        """x of A x = b (``b`` a vector or columns)."""
        if self.superlu is not None:
            return self.superlu.solve(b)
        b = np.asarray(b, dtype=float)
        if b.ndim == 1:
            return self.qdldl.solve(b)
        return np.stack([self.qdldl.solve(np.ascontiguousarray(c)) for c in b.T], axis=1) \
            if b.shape[1] else np.zeros_like(b)


class _Kkt:
    """The ``expand`` step without its inequality constraints, factored once.

    With r = B z + b and Q u = r the optimality conditions are the symmetric quasi-definite
    system [[-Q, B], [Bᵀ, R²]] [u; z] = [-b; R² z0], bordered by the energy-balance rows
    E z = -c (Schur complement on the few rows).  Quasi-definite matrices factor stably
    without pivoting in any symmetric order, so an LDLᵀ factor (:class:`_Ldl`) serves; up
    to three steps of iterative refinement follow.  ``previous``: the factor of the step
    before, whose order the next reuses where the pattern is the same.
    :meth:`solve` may border it by more equality rows F z = f (conditions held by
    :func:`_solve_reduced`), each solved against the factor once (:meth:`column`)."""

    def __init__(self, pb: _Problem, previous: _Ldl | None = None, superlu: bool = False):
        B, b, reg = _expanded_least_squares(pb)
        z0 = pb.x0 / pb.x_scale
        E, c = _energy_balance(pb)
        E = E * pb.x_scale
        if pb.flexibility is None:
            Q = sp.identity(b.size, format="csc")
        else:  # Q = blockdiag(K̃) per mode; rᵀQ⁻¹r = (Dr)ᵀ(DQD)⁻¹(Dr) with D = diag(Q)^-1/2:
            # unit diagonal, force and moment rows alike
            Q = sp.block_diag([pb.flexibility.Q] * pb.omega.size, "csc")
            D = sp.diags(1.0 / np.sqrt(Q.diagonal()))
            Q, B, b = (D @ Q @ D).tocsc(), (D @ B).tocsr(), D @ b
        self.K = sp.bmat([[-Q, B], [B.T, sp.diags(reg**2)]], format="csc")
        self.n_u, self.x_scale = b.size, pb.x_scale
        self.border = np.vstack([np.zeros((b.size, c.size)), E.T])
        self.rhs, self.rhs_eq = np.concatenate([-b, reg**2 * z0]), -c
        self.lu = _Ldl(self.K, previous, superlu)
        self.k_border = self.lu.solve(self.border)

    def column(self, row):
        """(border column, its solve) of the equality row ``row`` (on z)."""
        col = np.concatenate([np.zeros(self.n_u), row])
        return col, self.lu.solve(col)

    def solve(self, columns=(), values=()):
        """(x, relative residual) of the equality problem bordered by :meth:`column` pairs
        ``columns`` held at ``values`` (F z = f), or None when it is singular or stays
        inaccurate."""
        border, k_border, rhs_eq = self.border, self.k_border, self.rhs_eq
        if len(columns):
            border = np.hstack([border, np.stack([c for c, _ in columns], 1)])
            k_border = np.hstack([k_border, np.stack([s for _, s in columns], 1)])
            rhs_eq = np.concatenate([rhs_eq, values])
        schur = border.T @ k_border
        lu, K, rhs = self.lu, self.K, self.rhs

        def solve(r_main, r_eq):
            y = lu.solve(r_main)
            lam = np.linalg.solve(schur, border.T @ y - r_eq)
            return y - k_border @ lam, lam

        try:
            y, lam = solve(rhs, rhs_eq)
        except np.linalg.LinAlgError:  # dependent rows: leave it to IPOPT
            return None
        scale = np.linalg.norm(np.concatenate([rhs, rhs_eq]))
        for _ in range(3):
            res_main = rhs - K @ y - border @ lam
            res_eq = rhs_eq - border.T @ y
            residual = np.linalg.norm(np.concatenate([res_main, res_eq])) / max(scale, 1e-300)
            if residual < 1e-13:
                break
            dy, dlam = solve(res_main, res_eq)
            y, lam = y + dy, lam + dlam
        res_main = rhs - K @ y - border @ lam
        residual = float(np.linalg.norm(np.concatenate([res_main, rhs_eq - border.T @ y]))
                         / max(scale, 1e-300))
        if not np.all(np.isfinite(y)) or residual > 1e-8:
            return None
        return self.x_scale * y[self.n_u:], residual


def _solve_direct(pb: _Problem, reuse: dict | None = None):
    """The ``expand`` step without its inequality constraints (:class:`_Kkt`): (the
    factored system, x, relative residual), or None when the factorisation fails or the
    solve stays inaccurate.  ``reuse``: holds the last factor of the update (its order
    serves the next step's)."""
    reuse = {} if reuse is None else reuse
    try:
        kkt = _Kkt(pb, reuse.pop("factor", None))
        reuse["factor"] = kkt.lu
        out = kkt.solve()
        if out is None and kkt.lu.qdldl is not None:
            # QDLDL's factor, unpivoted, solved it inaccurately (a pivot lost to rounding):
            # SuperLU's, which pivots off a zero diagonal
            kkt = _Kkt(pb, superlu=True)
            out = kkt.solve()
    except RuntimeError:  # an exactly singular pivot (no regularisation)
        return None
    return None if out is None else (kkt, *out)


def _condition_rows(pb: _Problem):
    """The element parameters scaled by k0 as rows on z = x / x_scale: p = P z (k_ww, k_wθ,
    k_θθ, then a frame member's k, each a block of n elements)."""
    return (sp.csr_matrix(pb.par.matrix) @ sp.diags(pb.x_scale[:pb.n_q]) / pb.k0).tocsr()


def _condition_values(p, n: int, kind: str) -> list:
    """The element conditions (each ≥ the margin) from the element parameters ``p`` scaled
    by k0 (numbers or CasADi expressions; blocks of ``n`` elements as
    :func:`_condition_rows` orders them): a bar's k; a beam's k_ww, k_θθ and
    k_ww k_θθ - k_wθ²; a frame member's those and its bar's k.  The one place of these
    formulas (:func:`_constraints`, :func:`_solve_reduced`)."""
    if kind == "bar":
        return [p]
    ww, wt, tt = p[:n], p[n:2 * n], p[2 * n:3 * n]
    return [ww, tt, ww * tt - wt**2] + ([p[3 * n:]] if kind == "frame" else [])


def _solve_reduced(pb: _Problem, kkt: _Kkt, x, max_iter: int):
    """The convex step whose direct point ``x`` breaks element conditions, as a small
    problem on the parameters those elements read: ((success, status, stats), x) or None.

    With the parameters v of a set S held (rows e_sᵀ z = v bordering the factored system),
    the rest of the step is an equality problem, so its solution z(v) = z_u + G (v - v_u) is
    affine in v and the objective above its direct minimum is ½ (v - v_u)ᵀ H (v - v_u),
    H = [S⁻¹]_SS of the bordered system's Schur complement S (the energy balance eliminated):
    the step is exactly the small problem min ½ (v - v_u)ᵀ H (v - v_u) under the element
    conditions at z(v), as long as every condition that binds reads S alone.  Clarabel solves
    it as a cone program (:func:`_conic_reduced`; IPOPT, :func:`_ipopt_reduced`, where it
    does not or :data:`REDUCED_SOLVER` says so) with every condition of the elements that
    read S (:func:`_condition_values`' formulas); elements still broken at the point found,
    and elements whose condition binds but which read a parameter outside S (its multiplier
    pushes on that one too), free their parameters, for up to :data:`REDUCED_ROUNDS`
    rounds.  The point is then solved by the bordered system itself.  Uniform mass
    parameters are left to the whole step."""
    if pb.mmap is not None:
        return None
    P = _condition_rows(pb)
    n, kind = pb.par.n_elements, pb.disc.kind
    blocks = P.shape[0] // n
    z_u = x / pb.x_scale
    free, columns = np.zeros(0, dtype=int), {}
    x_new, n_e, stats, used = x, kkt.border.shape[1], None, []
    binding = np.zeros(0, dtype=int)   # elements whose condition binds in the small problem
    for _ in range(REDUCED_ROUNDS):
        g, lower = _constraints(pb, x_new)
        broken = np.unique(np.flatnonzero(~(g > lower)) % n)
        need = np.union1d(broken, binding)
        rows = (np.arange(blocks)[:, None] * n + need[None, :]).ravel()
        wider = np.union1d(free, P[rows].indices)
        if not broken.size and wider.size == free.size:
            # every condition holds and every one that binds reads S alone: the small
            # problem's optimality conditions are the step's
            return (True, stats["return_status"], stats), x_new
        if wider.size == free.size or wider.size > REDUCED_SIZE:
            return None
        free = wider
        for s in free.tolist():
            if s not in columns:
                columns[s] = kkt.column(np.eye(1, z_u.size, s).ravel())
        border = np.hstack([kkt.border, np.stack([columns[s][0] for s in free], 1)])
        k_border = np.hstack([kkt.k_border, np.stack([columns[s][1] for s in free], 1)])
        try:
            inverse = np.linalg.inv(border.T @ k_border)
        except np.linalg.LinAlgError:
            return None
        H = inverse[n_e:, n_e:]
        H = 0.5 * (H + H.T)
        G = (k_border @ inverse[:, n_e:])[kkt.n_u:]          # z(v) = z_u + G (v - v_u)
        # the elements whose parameters S moves directly: their conditions in the problem
        touched = np.unique(np.flatnonzero(np.diff(P[:, free].tocsr().indptr)) % n)
        rows = (np.arange(blocks)[:, None] * n + touched[None, :]).ravel()
        p_u, D = P[rows] @ z_u, P[rows] @ G
        # whitened, v - v_u = T w with Tᵀ H T = I: the objective ½ wᵀw, so that a solver's
        # stopping rule measures the objective, whatever the spread of H's eigenvalues
        h, V = np.linalg.eigh(H)
        if not h[0] > 0.0:
            return None
        T = V / np.sqrt(h)
        A_w = D @ T
        sol, info = (_conic_reduced(p_u, A_w, touched.size, kind, pb.margin)
                     if REDUCED_SOLVER == "clarabel" else (None, None))
        if sol is None:   # IPOPT when the cone program is not solved (or on request)
            sol, info = _ipopt_reduced(p_u, A_w, touched.size, kind, pb.margin, max_iter)
            if sol is None:
                return None
        used.append(info["solver"])
        stats = {"return_status": str(info.get("return_status")),
                 "iter_count": int(info.get("iter_count", 0)),
                 "reduced_parameters": int(free.size), "reduced_solvers": used}
        # the point of those parameters by the bordered solve itself (refined), not by the
        # affine map: the map carries the Schur complement's rounding into the energy
        # balance (measured 2e-9 on a 40-element bar, against 1e-16)
        v_opt = z_u[free] + T @ np.array(sol["x"]).ravel()
        exact = kkt.solve([columns[s] for s in free], v_opt)
        if exact is None:
            return None
        x_new = exact[0]
        # a condition that binds pushes on every parameter its element reads: one outside S
        # (a neighbour's) would then not be at its optimum, so those elements join S
        slack = np.array(sol["g"]).ravel() - pb.margin
        binding = touched[np.unique(np.flatnonzero(slack < REDUCED_BINDING) % touched.size)]
    return None


def _conic_reduced(p, A, n: int, kind: str, margin: float):
    """The reduced problem of :func:`_solve_reduced` as the cone program it is: min ½ wᵀw
    with every condition of :func:`_condition_values` at p + A w at least margin +
    :data:`REDUCED_LIFT`, each element's k_ww k_θθ - k_wθ² ≥ m (with k_ww, k_θθ ≥ m) the
    second-order cone ‖(2 k_wθ, 2√m, k_ww - k_θθ)‖ ≤ k_ww + k_θθ.  Clarabel solves it.  Its
    point meets the cones to its feasibility tolerance only (measured up to 2.8e-9 below
    the bound on the semi-rigid portal's draws): a point more than half the lift short of
    it is solved once more with the bound raised by twice the shortfall, and refused if
    still short (the lift is there for the bordered solve's rounding, 1e-11).  Returns
    ({"x", "g"}, info) or (None, None)."""
    import clarabel

    m, blocks = A.shape[1], A.shape[0] // n
    ww, wt, tt = (slice(k * n, (k + 1) * n) for k in range(3))
    linear = [slice(0, n)] if kind == "bar" else [ww, tt] + (
        [slice(3 * n, blocks * n)] if kind == "frame" else [])
    rows = [-A[part] for part in linear]            # k ≥ m: s = p - m + A w ≥ 0
    cones = [clarabel.NonnegativeConeT(sum(r.shape[0] for r in rows))]
    if kind != "bar":                                # s = (a + b, 2c, 2√m, a - b) in the cone
        a, c, b = A[ww], A[wt], A[tt]
        rows.append(-np.stack([a + b, 2 * c, np.zeros_like(a), a - b], axis=1)
                    .reshape(4 * n, m))
        cones += [clarabel.SecondOrderConeT(4)] * n
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-10
    # one thread, QDLDL: its default factorisation (faer) starts a pool of threads in this
    # process on larger problems, and a pool of fits forked from it after that waited for
    # ever on them (the bench's portal diagnosis after an update in process, stop 79);
    # sequential, the same rounding on every run
    settings.max_threads = 1
    settings.direct_solve_method = "qdldl"
    P, A_c = sp.identity(m, format="csc"), sp.csc_matrix(np.vstack(rows))
    bound, iterations = margin + REDUCED_LIFT, 0
    for _ in range(2):
        rhs = [p[part] - bound for part in linear]
        if kind != "bar":
            rhs.append(np.stack([p[ww] + p[tt], 2 * p[wt], np.full(n, 2 * np.sqrt(bound)),
                                 p[ww] - p[tt]], axis=1).ravel())
        solution = clarabel.DefaultSolver(P, np.zeros(m), A_c, np.concatenate(rhs), cones,
                                          settings).solve()
        iterations += int(solution.iterations)
        if str(solution.status) != "Solved":
            return None, None
        w = np.asarray(solution.x)
        g = np.concatenate(_condition_values(p + A @ w, n, kind))
        short = margin + REDUCED_LIFT - float(g.min())
        if short <= 0.5 * REDUCED_LIFT:
            return {"x": w, "g": g}, {"solver": "clarabel",
                                      "return_status": str(solution.status),
                                      "iter_count": iterations}
        bound += 2.0 * short
    return None, None


def _ipopt_reduced(p, A, n: int, kind: str, margin: float, max_iter: int):
    """The reduced problem of :func:`_solve_reduced` by IPOPT, the conditions as CasADi
    expressions (:func:`_condition_values`) held margin + :data:`REDUCED_LIFT` or above.
    Returns ({"x", "g"}, info) or (None, None)."""
    # MX, not SX: the conditions read dense affine maps of w, and SX expands them into
    # scalar graphs from which IPOPT's solver is built with a dense symbolic Hessian
    # (~rows × n² nodes): on the semi-rigid portal's generic update, building its 21
    # solvers took 6.8 s; as matrix products 0.15 s (parameters the same to 7e-9)
    w = ca.MX.sym("w", A.shape[1])
    values = _condition_values(ca.DM(p) + ca.mtimes(ca.DM(A), w), n, kind)
    problem = {"x": w, "f": 0.5 * ca.sumsqr(w), "g": ca.vertcat(*values)}
    # IPOPT twice: from the direct point, then from its point with the objective scaled
    # to one there (its stopping rule is absolute, and a step that a few elements cross
    # may cost 1e-5 of the objective: measured, the first solve's objective 1e-5 above
    # a conic solver's, the second's within 1e-8, in 10-15 more iterations)
    sol, info, scaling, iterations = None, None, 1.0, 0
    for _ in range(2):
        solver = ca.nlpsol("reduced_step", "ipopt", problem, {
            "ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
            "ipopt.mu_strategy": "adaptive", "ipopt.max_iter": max_iter,
            "ipopt.tol": 1e-10, "ipopt.acceptable_tol": 1e-8,
            "ipopt.obj_scaling_factor": scaling,
            # the conditions as stated (IPOPT relaxes them by 1e-8): the step's point
            # satisfies them strictly, as a direct one does
            "ipopt.bound_relax_factor": 0.0})
        try:
            out = solver(x0=np.zeros(A.shape[1]) if sol is None else sol["x"],
                         lbg=margin + REDUCED_LIFT, ubg=np.inf)
        except RuntimeError:
            return None, None
        if not solver.stats().get("success"):
            if sol is None:
                return None, None
            break    # (the first solve's point stands)
        sol, info = out, solver.stats()
        iterations += int(info.get("iter_count", 0))
        scaling = 1.0 / max(float(sol["f"]), 1e-300)
    return ({"x": np.array(sol["x"]).ravel(), "g": np.array(sol["g"]).ravel()},
            {"solver": "ipopt", "return_status": str(info.get("return_status")),
             "iter_count": iterations})


def _solve_step(pb: _Problem, x_start, max_iter: int, solver: str, reuse=None):
    """One convex ``expand`` step: direct when no inequality is active at the direct solution
    (the problem is convex, so that point is its optimum), the reduced problem of the
    elements it breaks when some are (:func:`_solve_reduced`, on the same factorisation:
    Clarabel, IPOPT where Clarabel fails), IPOPT on the whole step when that fails or on
    request.  Returns
    ((success, status, stats), (x, shapes), solver used).  ``reuse``: of
    :func:`_solve_direct`."""
    if solver == "auto":
        direct = _solve_direct(pb, reuse)
        if direct is not None:
            kkt, x, residual = direct
            g, lower = _constraints(pb, x)
            if np.all(g > lower):
                info = {"return_status": DIRECT_STATUS, "iter_count": 0,
                        "kkt_residual": residual}
                return (True, DIRECT_STATUS, info), (x, pb.phi0), "direct"
            reduced = _solve_reduced(pb, kkt, x, max_iter)
            if reduced is not None:
                return reduced[0], (reduced[1], pb.phi0), "reduced"
    return _solve_ipopt(pb, "expand", x_start, max_iter) + ("ipopt",)


def _constraints(pb: _Problem, x):
    """Feasibility constraints g(x) >= lower bounds: element stiffness scaled by k0 (>=
    margin) and the mass conditions (>= MASS_MARGIN); CasADi expressions for a symbolic x,
    numbers for an array (the direct step's check: the same formulas, a twentieth of the
    time)."""
    numeric = isinstance(x, np.ndarray)
    p = (pb.par.matrix @ x[:pb.n_q] if numeric
         else ca.mtimes(_dm(pb.par.matrix), x[:pb.n_q])) / pb.k0
    g = _condition_values(p, pb.par.n_elements, pb.disc.kind)
    lower = [np.full(sum(e.shape[0] for e in g), pb.margin)]
    if pb.mmap is not None:
        mass = pb.mmap.conditions(x[pb.n_q:])
        g += mass
        lower.append(np.full(len(mass), MASS_MARGIN))
    if numeric:
        return np.concatenate([np.atleast_1d(np.asarray(e, dtype=float)).ravel()
                               for e in g]), np.concatenate(lower)
    return ca.vertcat(*g), np.concatenate(lower)


def _dm(matrix) -> ca.DM:
    m = sp.csc_matrix(matrix)
    m.sort_indices()
    return ca.DM(ca.Sparsity(m.shape[0], m.shape[1], m.indptr.tolist(), m.indices.tolist()),
                 m.data)


def _setup(model, parameterisation, regularisation, all_dofs_measured: bool):
    """The discretisation, the parameterisation object and the regularisation to use."""
    if regularisation is None:
        regularisation = default_regularisation(all_dofs_measured)
    disc = discretise(model) if isinstance(model, Model) else model
    par = parameterisation if isinstance(parameterisation, Parameterisation) else \
        parameterisation_for(disc.kind, parameterisation, disc.n_elements, disc.element_length)
    return disc, par, regularisation


@one_blas_thread
def update_generic(model: Model | Discretisation, measured: MeasuredModes, *,
                   parameterisation: str | Parameterisation = "nodal", method: str = "expand",
                   noise: float = DEFAULT_SHAPE_NOISE, regularisation: float | None = None,
                   margin: float = 1e-3, q0=None, max_iter: int = 500,
                   full_shapes=None, refinements: int = 2,
                   update_mass: bool = False, solver: str = "auto",
                   weighting: str = "auto") -> UpdateResult:
    """Update generic stiffness parameters by the equation error (see module docstring).

    ``model`` is the initial model (or its discretisation); ``q0`` may replace its parameter
    values as the starting point (it may violate the constraints).  ``full_shapes``
    (n_dof, n_modes), when every DOF was measured, replaces the expansion.  With ``expand``,
    ``refinements`` re-expansions with the updated model follow the first solve (each
    re-solves the convex problem; the regularisation stays anchored at the initial model).
    ``bilinear`` starts from the ``expand`` solution.  ``update_mass`` adds the uniform
    generic mass parameters (beam m11, m12, m14, m22 of eq. 17; bar β of eq. 2) with their
    positive-definiteness conditions (``expand`` only).  ``solver="auto"`` solves each
    convex ``expand`` step by one sparse KKT factorisation and keeps that point when no
    inequality is active there (convexity makes it the optimum), else calls IPOPT;
    ``solver="ipopt"`` always calls IPOPT.  ``weighting`` is ``"rows"`` (the module
    docstring's W), ``"energy"`` (residual forces in the flexibility metric of the
    initial model, for fine meshes) or ``"auto"`` (rows up to AUTO_ENERGY_ELEMENTS
    elements, energy above, with ``method="expand"``; the result's ``stats["weighting"]``
    says which).  Never raises for a failed solve: the result's
    ``success``/``status`` say so and ``ok`` is False.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r} (one of {', '.join(METHODS)})")
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver {solver!r} (one of {', '.join(SOLVERS)})")
    if weighting not in WEIGHTINGS:
        raise ValueError(f"unknown weighting {weighting!r} (one of {', '.join(WEIGHTINGS)})")
    if update_mass and method != "expand":
        raise ValueError("mass parameters are updated with method='expand' only")
    if weighting == "auto":
        n_elements = model.elements if isinstance(model, Model) else model.n_elements
        weighting = ("energy" if method == "expand" and n_elements > AUTO_ENERGY_ELEMENTS
                     else "rows")
    if weighting == "energy" and method != "expand":
        raise ValueError("weighting='energy' is available with method='expand' only")
    if measured.frequency_only and full_shapes is None:
        raise GfeInputError(measured.source, "sensors", "the generic-element update needs "
                            "mode shapes at 3 or more sensors: " + measured.without_shapes_note())
    disc, par, regularisation = _setup(model, parameterisation, regularisation,
                                       full_shapes is not None)
    start = time.perf_counter()
    if q0 is None:   # the initial model's parameters, once (every refinement anchors there)
        q0 = par.fit(disc.stiffness_params)

    def prepare(expansion_disc=None, kmap=None):
        return _prepare(disc, par, measured, noise, regularisation, margin, q0, full_shapes,
                        expansion_disc, update_mass, weighting, kmap)

    pb = prepare()
    notes, reuse = [], {}
    (success, status, info), (x_opt, phi_opt), used = _solve_step(pb, pb.x0, max_iter, solver,
                                                                  reuse)
    solvers, reduced_by = [used], list(info.get("reduced_solvers", []))
    for done in range(refinements if full_shapes is None else 0):
        if not success:
            break
        updated = _updated_discretisation(pb, x_opt)
        pb = prepare(updated, pb.kmap)  # same initial model: same stiffness map
        (success, status, info), (x_new, phi_opt), used = _solve_step(pb, x_opt, max_iter,
                                                                      solver, reuse)
        solvers.append(used)
        reduced_by += info.get("reduced_solvers", [])
        step = np.max(np.abs(x_new - x_opt) / pb.x_scale)
        x_opt = x_new
        info["refinements"] = done + 1
        if step < 1e-6:
            break
    if method == "bilinear":
        if not success:
            notes.append(f"the expand start did not converge ({status})")
        (success, status, info), (x_opt, phi_opt) = _solve_ipopt(pb, method, x_opt, max_iter)
        solvers.append("ipopt")
    info["steps"] = solvers
    # the solver of the hardest problem solved: IPOPT (on a whole or a reduced step), else
    # Clarabel (on reduced steps), else the direct factorisation alone
    by = "ipopt" if "ipopt" in solvers or "ipopt" in reduced_by else (
        "clarabel" if "reduced" in solvers else "direct")
    result = _finish(pb, method, by, x_opt, phi_opt,
                     status, success, info, time.perf_counter() - start, notes)
    result.stats = {**(result.stats or {}), "weighting": weighting}
    return result


def _solve_ipopt(pb: _Problem, method: str, x_start, max_iter: int):
    """One IPOPT solve; returns ((success, status, stats), (x, free-DOF shapes))."""
    n_x, n_free, m = pb.x0.size, pb.phi0.shape[0], pb.omega.size
    # -- decision variables (scaled to order one) -----------------------------------------
    symbol = ca.MX if method == "expand" else ca.SX  # MX keeps sparse products whole
    z_x = symbol.sym("z_x", n_x)
    x = pb.x_scale * z_x
    variables, start_values = [z_x], [np.asarray(x_start) / pb.x_scale]
    # -- objective ------------------------------------------------------------------------
    lifted = None
    if method == "expand":
        # lifted: residual variables u = B z + b ("rows") or L u = B z + b with Q = L Lᵀ
        # ("energy"), objective uᵀu: no BᵀB is formed, and IPOPT converges to its tolerance
        # (the unlifted ||B z + b||² stalled at "acceptable" on fine meshes; the energy
        # metric as uᵀQu with Q u = B z + b failed in the step computation at N = 2000)
        B, b, _ = _expanded_least_squares(pb)
        u = ca.MX.sym("u", b.size)
        r_start = B @ start_values[0] + b
        if pb.flexibility is None:
            J, lifted = ca.sumsqr(u), u - ca.mtimes(_dm(B), z_x)
            start_values.append(r_start)
        else:  # Q = L Lᵀ: L u = B z + b, J = uᵀu = rᵀ Q⁻¹ r
            L = pb.flexibility.lower_blocks(pb.omega.size)
            J, lifted = ca.sumsqr(u), ca.mtimes(_dm(L), u) - ca.mtimes(_dm(B), z_x)
            start_values.append(spsolve_triangular(L.tocsr(), r_start, lower=True))
        variables.append(u)
    else:
        pat = pb.kmap.pattern
        K = ca.SX(ca.Sparsity(pat.shape[0], pat.shape[1], pat.indptr.tolist(),
                              pat.indices.tolist()),
                  ca.mtimes(_dm(pb.kmap.S), x) + pb.kmap.extra)
        Mdm, Cdm = _dm(pb.M), _dm(pb.C)
        phi_scale = np.maximum(np.abs(pb.phi0).max(axis=1), 1e-12)
        z_phi = ca.SX.sym("z_phi", n_free, m)
        variables.append(ca.vec(z_phi))
        start_values.append((pb.phi0 / phi_scale[:, None]).ravel(order="F"))
        J, misfit = 0, 0
        for j in range(m):
            phi = phi_scale * z_phi[:, j]
            r = ca.mtimes(K, phi) - pb.omega[j] ** 2 * ca.mtimes(Mdm, phi)
            J += ca.sumsqr(pb.row_weights[:, j] * r)
            misfit += ca.sumsqr(ca.mtimes(Cdm, phi) - pb.y[:, j])
        J = J / (n_free * m * pb.eq_scale) + misfit / (max(pb.noise, 1e-6) ** 2 * pb.y.size)
    J += pb.regularisation / n_x * ca.sum1(pb.x_weights * (z_x - pb.x0 / pb.x_scale) ** 2)
    # -- constraints ----------------------------------------------------------------------
    g, lbg = _constraints(pb, x)
    ubg = np.full(lbg.size, np.inf)
    if method == "expand":
        A, c = _energy_balance(pb)
        g = ca.vertcat(g, ca.mtimes(ca.DM(A), x) + c, lifted)
        lbg = np.concatenate([lbg, np.zeros(c.size), b])
        ubg = np.concatenate([ubg, np.zeros(c.size), b])
    # -- solve ----------------------------------------------------------------------------
    solver = ca.nlpsol("equation_error", "ipopt", {"x": ca.vertcat(*variables), "f": J, "g": g},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                        # the adaptive barrier update copes with the wide curvature range
                        # of fine meshes (N >= 1000 stalled with the monotone default)
                        "ipopt.mu_strategy": "adaptive",
                        "ipopt.max_iter": max_iter, "ipopt.tol": 1e-8,
                        "ipopt.acceptable_tol": 1e-6})
    try:
        sol = solver(x0=np.concatenate(start_values), lbg=lbg, ubg=ubg)
    except RuntimeError as exc:  # CasADi raises on evaluation errors
        raise GfeSolverError(f"IPOPT failed: {exc}") from exc
    stats = solver.stats()
    xs = np.array(sol["x"]).ravel()
    x_opt = pb.x_scale * xs[:n_x]
    phi_opt = pb.phi0 if method == "expand" else \
        xs[n_x:].reshape((n_free, m), order="F") * phi_scale[:, None]
    info = {k: stats.get(k) for k in ("return_status", "iter_count")}
    return ((bool(stats.get("success")), str(stats.get("return_status")), info),
            (x_opt, phi_opt))


# -------------------------------------------------------------------------------------------
# cvxpy: the convex SDP cross-check
# -------------------------------------------------------------------------------------------


def update_sdp(model: Model | Discretisation, measured: MeasuredModes, *,
               parameterisation: str | Parameterisation = "nodal",
               noise: float = DEFAULT_SHAPE_NOISE, regularisation: float | None = None,
               margin: float = 1e-3, full_shapes=None, solver: str = "CLARABEL",
               update_mass: bool = False, weighting: str = "rows") -> UpdateResult:
    r"""The ``expand`` problem as a convex SDP: same objective, with every element stiffness
    semidefinite, :math:`P_e / k_0 \succeq m I` where :math:`K_e = H^T P_e H / L^3`
    (bar: :math:`k_e \ge m k_0`), and with ``update_mass`` the mass blocks positive definite
    (linear matrix inequalities in m).  Solved with cvxpy (Clarabel by default, or SCS).
    ``weighting="energy"`` is lifted as in IPOPT (L u = B z + b, Q = L Lᵀ)."""
    import cvxpy as cp

    if weighting not in WEIGHTINGS:
        raise ValueError(f"unknown weighting {weighting!r} (one of {', '.join(WEIGHTINGS)})")
    disc, par, regularisation = _setup(model, parameterisation, regularisation,
                                       full_shapes is not None)
    start = time.perf_counter()
    pb = _prepare(disc, par, measured, noise, regularisation, margin, None, full_shapes,
                  None, update_mass, weighting)
    B, b, reg = _expanded_least_squares(pb)
    z = cp.Variable(pb.x0.size)
    z0 = pb.x0 / pb.x_scale
    constraints = []
    if pb.flexibility is None:
        objective = cp.sum_squares(B @ z + b)
    else:
        u = cp.Variable(b.size)
        constraints.append(pb.flexibility.lower_blocks(pb.omega.size) @ u == B @ z + b)
        objective = cp.sum_squares(u)
    objective += cp.sum_squares(cp.multiply(reg, z - z0))
    p = (par.matrix @ sp.diags(pb.scale) / pb.k0) @ z[:pb.n_q]
    n = par.n_elements
    if disc.kind == "bar":
        constraints.append(p >= margin)
    else:
        constraints += [cp.bmat([[p[e], p[n + e]], [p[n + e], p[2 * n + e]]]) >> margin * np.eye(2)
                        for e in range(n)]
    if pb.mmap is not None:
        mass = z[pb.n_q:] * 0.1
        if disc.kind == "bar":
            constraints.append(mass[0] <= 0.25 - MASS_MARGIN)
        else:  # eq. 17 is positive definite iff its two R-invariant 2x2 blocks are
            m11, m12, m14, m22 = (mass[i] for i in range(4))
            m24 = 1.0 / 6.0 - m11 / 2.0 + m12 + m14 - m22
            eye = MASS_MARGIN * np.eye(2)
            constraints += [cp.bmat([[0.5, m12 - m14], [m12 - m14, m22 - m24]]) >> eye,
                            cp.bmat([[2 * m11 - 0.5, m12 + m14],
                                     [m12 + m14, m22 + m24]]) >> eye]
    A, b_energy = _energy_balance(pb)
    constraints.append((A @ sp.diags(pb.x_scale)) @ z + b_energy == 0)
    problem = cp.Problem(cp.Minimize(objective), constraints)
    if not problem.is_dcp():
        raise GfeSolverError("the SDP variant is not DCP (a formulation bug)")
    try:
        # Clarabel on one thread, as the reduced step's (:func:`_conic_reduced`): threads
        # it starts here would hang a pool of fits forked later from this process
        problem.solve(solver=solver, **({"max_threads": 1} if solver.upper() == "CLARABEL"
                                        else {}))
    except cp.error.SolverError as exc:
        raise GfeSolverError(f"cvxpy/{solver} failed: {exc}") from exc
    status = str(problem.status)
    success = status == cp.OPTIMAL
    x = pb.x_scale * (np.asarray(z.value).ravel() if z.value is not None else z0)
    stats = {"return_status": status, "solver": solver,
             "iter_count": problem.solver_stats.num_iters,
             "t_wall_total": problem.solver_stats.solve_time}
    return _finish(pb, "expand", f"cvxpy-{solver.lower()}", x, pb.phi0, status, success, stats,
                   time.perf_counter() - start, [])



def active_constraints(result: UpdateResult, tol: float = 1e-6) -> list[int]:
    """Elements on a bound of the solver's own constraints: IPOPT k_ww, k_θθ or
    k_ww k_θθ - k_wθ² at the margin; SDP λ_min(P_e / k0) at the margin (bar: k / k0)."""
    p = {k: np.asarray(v) / result.k0 for k, v in result.element_parameters.items()}
    if "k" in p:
        slack = p["k"] - result.margin
    elif result.solver.startswith("cvxpy"):
        P = np.stack([np.stack([p["k_ww"], p["k_wt"]], -1),
                      np.stack([p["k_wt"], p["k_tt"]], -1)], -2)
        slack = np.linalg.eigvalsh(P)[:, 0] - result.margin
    else:
        slack = np.min([p["k_ww"], p["k_tt"], p["k_ww"] * p["k_tt"] - p["k_wt"] ** 2],
                       axis=0) - result.margin
    return np.flatnonzero(slack <= tol).tolist()


def cross_check(ipopt: UpdateResult, sdp: UpdateResult, tol: float = 1e-4) -> dict:
    """Compare an IPOPT and an SDP solution of the same problem: relative parameter and
    objective differences, constraint activity, and whether they agree within ``tol``."""
    scale = np.maximum(np.abs(ipopt.q), np.abs(ipopt.scale))
    param = float(np.max(np.abs(ipopt.q - sdp.q) / scale))
    objective = float(abs(ipopt.objective - sdp.objective) / max(abs(sdp.objective), 1e-300))
    out = {"parameter_difference": param, "objective_difference": objective,
           "active_ipopt": active_constraints(ipopt), "active_sdp": active_constraints(sdp),
           "both_ok": ipopt.ok and sdp.ok}
    out["agree"] = bool(out["both_ok"] and param <= tol and objective <= tol)
    return out

"""From a :class:`~gfe_opt.model.Model` to element and global (sparse) matrices.

The stiffness of every element is held as *generic parameters* (eq. 2 for a bar, eq. 11 for a
beam), so the updating engine can replace them; effects that a generic element cannot hold
(geometric stiffness of an axial load, a Winkler foundation, springs) are kept apart as extra
terms.  Global DOFs are node-major: a beam node i has ``w`` at 2i and θ at 2i+1 (physical
rotation in rad), a bar node i has ``u`` at i.

Effects do not touch matrices themselves: each tells a :class:`Builder` what it changes
(:meth:`~gfe_opt.effects.EffectType.contribute`), and the builder makes the elements:

* EI(x) (bar: EA(x)) = EI · Π f_i(x) over the rigidity factors; an element where the
  product differs from 1 gets the exact static stiffness of its varying rigidity
  (:func:`~gfe_opt.elements.flexibility_parameters`, Gauss points graded towards kinks);
* ρA(x) = ρA · Π g_i(x): the element mass gains ∫ ρA (g − 1) N Nᵀ dx (Hermite or linear N);
* shear (Timoshenko), element stiffness terms per unit length, point masses and springs
  (through the shape functions at their position), rotational end springs (a clamped end's
  rotation is released and held by the spring instead).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from typing import Callable

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .model import Model

#: free DOFs up to which a beam's or bar's modes come from LAPACK on the dense matrices;
#: above, from shift-invert Lanczos on the sparse ones, whose cost grows as the DOFs where
#: the dense solve's grows as their cube.  A speed choice, not a result: the shapes agree
#: to 1e-10 and move as smoothly with a parameter either way (a crack moved by 1e-11 of
#: the length: second differences 6e-11 sparse, 5e-11 dense at 100 elements; 2e-10 and
#: 4e-10 at 200), the frequencies are the shapes' Rayleigh quotients either way.  Measured
#: side by side, ``python scripts/bench.py --parts dense`` (9 modes, one BLAS thread): the
#: sparse solve is the faster from 152 free DOFs on beams (1.91 against 2.00 ms; 1.89
#: against 1.83 at 144) and from 180 on bars (2.17 against 2.49; 2.12 against 2.05 at
#: 160); 3.3 against 13.8 ms at a beam's 400, 4.7 against 633 ms at a bar's 1 500
DENSE_SOLVE_DOFS = 148
#: ... and up to which their eigen-derivatives' bordered systems are solved dense; above,
#: by Nelson's sparse form (the same derivatives to 3e-8 of the largest, the systems'
#: own conditioning at 400 DOFs).  The same bench: Nelson's form is the faster from 128
#: free DOFs on beams (2.90 against 3.03 ms, 9 modes and 4 parameters; 2.83 against 2.69
#: at 120) and from 140 on bars; 5.2 against 40.9 ms at a beam's 400.  The campaigns'
#: beams (30 to 60 elements, at most 122 free DOFs) stay dense on both counts
DENSE_DERIVATIVE_DOFS = 124


@dataclass(frozen=True)
class Discretisation:
    """Element data of a model, ready for assembly and updating (all SI).

    stiffness_params:
        generic parameters per element, arrays of shape (n_elements,): beam ``k_ww, k_wt,
        k_tt`` [N m²] (eq. 11 with K = L⁻³[...]); bar ``k`` = EA [N].
    mass:
        element mass matrices in *physical* DOFs, (n_elements, n, n) [kg, kg m, kg m²].
    extra_stiffness:
        element stiffness terms outside the generic family, physical DOFs, (n_elements, n, n).
    nodal_stiffness:
        ``(dof, value)`` pairs added to the global diagonal (support springs).
    """

    kind: str
    nodes: np.ndarray
    element_length: float
    stiffness_params: dict
    mass: np.ndarray
    extra_stiffness: np.ndarray
    nodal_stiffness: tuple
    constrained: np.ndarray
    eigenvalue_scale: float
    #: Timoshenko g = 12EI/(κGAL²) per element (None: Euler–Bernoulli); sensors between
    #: nodes are interpolated with it (:func:`~gfe_opt.elements.timoshenko_deflection`)
    shear_g: np.ndarray | None = None

    @property
    def n_elements(self) -> int:
        return len(self.nodes) - 1

    @property
    def dofs_per_node(self) -> int:
        return 2 if self.kind == "beam" else 1

    @property
    def n_dof(self) -> int:
        return self.dofs_per_node * len(self.nodes)

    @cached_property
    def free(self) -> np.ndarray:
        """The unconstrained DOFs (read-only; kept: the modal solve, the observation and the
        eigen-derivatives ask for them at every evaluation)."""
        return free_dofs(self.n_dof, np.asarray(self.constrained, dtype=np.int64).tobytes())

    @property
    def dense_solve(self) -> bool:
        """The modal solve on the dense pencil (LAPACK) up to :data:`DENSE_SOLVE_DOFS` free
        DOFs, shift-invert Lanczos on the sparse one above (a speed choice:
        :mod:`gfe_opt.modal`)."""
        return self.free.size <= DENSE_SOLVE_DOFS

    @property
    def dense_derivatives(self) -> bool:
        """The eigen-derivatives' bordered systems dense up to :data:`DENSE_DERIVATIVE_DOFS`
        free DOFs, Nelson's sparse form above (a speed choice: :mod:`gfe_opt.sensitivity`)."""
        return self.free.size <= DENSE_DERIVATIVE_DOFS

    def element_dofs(self) -> np.ndarray:
        """(n_elements, 2 n) global DOF indices of each element."""
        n = self.dofs_per_node
        return np.arange(self.n_elements)[:, None] * n + np.arange(2 * n)[None, :]

    def stiffness_elements(self, params=None) -> np.ndarray:
        """Generic element stiffness in physical DOFs, (n_elements, n, n)."""
        return stiffness_elements(self.kind, self.stiffness_params if params is None else params,
                                  self.element_length)

    def element_strain_energy(self, shapes, params=None) -> np.ndarray:
        r"""Twice the generic strain energy :math:`φ_e^T K_e φ_e` per element, (n_elements, n).

        Summed from relative deformations (eq. 11 = :math:`H^T P H`, bar: :math:`u_i - u_j`),
        which keeps full precision on fine meshes where forming :math:`K φ` cancels
        catastrophically (error ~ eps N⁴).
        """
        params = self.stiffness_params if params is None else params
        L = self.element_length
        u = shapes[self.element_dofs()]  # (n_elements, 2n, n_modes)
        if self.kind == "bar":
            return (params["k"] / L)[:, None] * (u[:, 0] - u[:, 1]) ** 2
        u = u * el.beam_dof_scaling(L)[:, None]
        d = np.einsum("ij,ejm->eim", el.BEAM_DEFORMATION_H, u)
        return (params["k_ww"][:, None] * d[:, 0] ** 2
                + 2 * params["k_wt"][:, None] * d[:, 0] * d[:, 1]
                + params["k_tt"][:, None] * d[:, 1] ** 2) / L**3

    def strain_energy(self, shapes, params=None) -> np.ndarray:
        """Twice the total strain energy :math:`φ^T K φ` of each column of ``shapes``."""
        energy = self.element_strain_energy(shapes, params).sum(axis=0)
        if np.any(self.extra_stiffness):   # (adding its zero would change no bit)
            u = shapes[self.element_dofs()]
            energy = energy + np.sum(u * (self.extra_stiffness @ u), axis=(0, 1))
        for dof, value in self.nodal_stiffness:
            energy = energy + value * shapes[dof] ** 2
        return energy

    def rigid_body_count(self) -> int:
        """How many rigid-body modes (ω = 0) the supports and springs leave: the motions
        w = a + b x, θ = b (bar: u = a) that vanish at the constrained DOFs and store no
        strain energy (a foundation or a spring to ground takes them away)."""
        import scipy.linalg as sla

        basis, null = _rigid_motions(self.kind, np.asarray(self.nodes, float).tobytes(),
                                     np.asarray(self.constrained, dtype=np.int64).tobytes())
        if null.shape[1] == 0:
            return 0
        motions = basis @ null
        k = motions.shape[1]
        # a rigid motion of the elements stores no strain energy (up to rounding): what the
        # foundation and springs store decides; combinations count (a free beam on one
        # spring still turns about it), so the k x k energy matrix by polarisation
        pairs = np.stack([motions[:, i] + motions[:, j] for i in range(k) for j in range(k)],
                         1)
        energy = self.strain_energy(np.hstack([motions, pairs]))
        single, both = energy[:k], energy[k:].reshape(k, k)
        E = 0.5 * (both - single[:, None] - single[None, :])
        u = motions[self.element_dofs()]
        Mr = np.einsum("eim,eij,ejn->mn", u, self.mass, u)
        lam = sla.eigh(0.5 * (E + E.T), Mr, eigvals_only=True)
        return int(np.sum(lam <= 1e-9 * self.eigenvalue_scale))

    def observation(self, measured) -> sp.csr_matrix:
        """The sensors of ``measured`` reading the DOFs (interpolated with the elements'
        Timoshenko g, if any: :func:`~gfe_opt.measured.sensor_matrix`)."""
        from .measured import sensor_matrix

        return sensor_matrix(self.nodes, self.kind, measured.x, measured.dof,
                             measured.source, shear_g=self.shear_g)

    def with_stiffness(self, params) -> "Discretisation":
        return replace(self, stiffness_params={k: np.asarray(v, float) for k, v in params.items()})

    def assemble_elements(self, matrices) -> sp.csr_matrix:
        """Sum element matrices (n_elements, n, n) into a global sparse matrix."""
        slot, indices, indptr = _assembly_pattern(self.n_elements, self.dofs_per_node)
        data = np.bincount(slot, weights=np.asarray(matrices, dtype=float).ravel(),
                           minlength=indices.size)
        return sp.csr_matrix((data, indices, indptr), shape=(self.n_dof, self.n_dof))

    def global_matrices(self, params=None) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Global (K, M) over all DOFs, boundary conditions not applied."""
        K = self._with_nodal(self.assemble_elements(self.stiffness_elements(params)
                                                    + self.extra_stiffness))
        M = self.assemble_elements(self.mass)
        return K.tocsr(), M.tocsr()

    def _with_nodal(self, K):
        """``K`` plus the nodal springs (end springs)."""
        if self.nodal_stiffness:
            dof, val = zip(*self.nodal_stiffness)
            K = K + sp.csr_matrix((val, (dof, dof)), shape=K.shape)
        return K

    def fixed_stiffness(self) -> sp.csr_matrix:
        """The part of K the generic parameters do not carry (geometric, foundation, point
        and end springs), all DOFs."""
        return self._with_nodal(self.assemble_elements(self.extra_stiffness))


@lru_cache(maxsize=16)
def _assembly_pattern(n_elements: int, per_node: int):
    """Where each entry of the element matrices lands in the global CSR data: (slot per
    element entry, indices, indptr), computed once per mesh (the fits assemble thousands of
    times; building the pattern each time cost more than the arithmetic)."""
    dofs = np.arange(n_elements)[:, None] * per_node + np.arange(2 * per_node)[None, :]
    rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
    cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
    n_dof = per_node * (n_elements + 1)
    pattern = sp.csr_matrix((np.arange(1, rows.size + 1, dtype=float), (rows, cols)),
                            shape=(n_dof, n_dof))
    pattern.sort_indices()
    key = rows.astype(np.int64) * n_dof + cols
    position = np.repeat(np.arange(n_dof), np.diff(pattern.indptr)).astype(np.int64) * n_dof \
        + pattern.indices
    slot = np.searchsorted(position, key)
    for array in (slot, pattern.indices, pattern.indptr):
        array.setflags(write=False)
    return slot, pattern.indices, pattern.indptr


def constrained_dofs(model: Model) -> np.ndarray:
    """Global DOFs fixed by the supports."""
    last = model.elements
    fixed = []
    for node, support in ((0, model.supports[0]), (last, model.supports[1])):
        if model.kind == "bar":
            if support == "fixed":
                fixed.append(node)
            continue
        w, t = 2 * node, 2 * node + 1
        fixed += {"pinned": [w], "clamped": [w, t], "sliding": [t], "free": []}[support]
    return np.array(sorted(fixed), dtype=int)


@dataclass(frozen=True)
class Factor:
    """A multiplier f(x) of the rigidity or of the mass per length; f = 1 outside
    ``support`` (``None``: anywhere).  ``breakpoints`` are kinks or jumps that element
    quadrature must not straddle; ``refine_scale`` grades the points towards them."""

    fn: Callable
    breakpoints: tuple = ()
    refine_scale: float | None = None
    support: tuple | None = None


#: Gauss points per element where a factor is smooth
GAUSS_ORDER = 8


@dataclass
class Builder:
    """What the effects of a model change; :meth:`discretisation` makes the elements."""

    model: Model
    rigidity: list = field(default_factory=list)
    mass: list = field(default_factory=list)
    shear_rigidity: float | None = None
    element_terms: list = field(default_factory=list)
    point_stiffness: list = field(default_factory=list)
    point_masses: list = field(default_factory=list)
    point_inertias: list = field(default_factory=list)
    end_springs: list = field(default_factory=list)

    # -- what effects call --------------------------------------------------------------
    def scale_rigidity(self, fn, breakpoints=(), refine_scale=None, support=None) -> None:
        """EI(x) (bar: EA(x)) is multiplied by ``fn(x)`` (vectorised)."""
        self.rigidity.append(Factor(fn, tuple(breakpoints), refine_scale, support))

    def scale_mass(self, fn, breakpoints=(), refine_scale=None, support=None) -> None:
        """ρA(x) is multiplied by ``fn(x)``."""
        self.mass.append(Factor(fn, tuple(breakpoints), refine_scale, support))

    def add_element_stiffness(self, per_element: Callable) -> None:
        """``per_element(L)`` is a (4, 4) stiffness in the scaled DOFs [w, Lθ, w, Lθ],
        the same for every element (axial load, foundation)."""
        self.element_terms.append(per_element)

    def add_point_stiffness(self, x: float, k: float) -> None:
        """A translational (bar: axial) spring to ground at x [m], k [N/m]."""
        self.point_stiffness.append((float(x), float(k)))

    def add_point_mass(self, x: float, m: float) -> None:
        """A mass m [kg] at x [m] (translation only)."""
        self.point_masses.append((float(x), float(m)))

    def add_point_inertia(self, x: float, J: float) -> None:
        """A rotary inertia J [kg m²] at x [m] (a beam: the kinetic energy J θ̇²/2 of a body
        that turns with the beam's slope there)."""
        self.point_inertias.append((float(x), float(J)))

    def add_end_spring(self, side: str, k: float, translation: bool = False) -> None:
        """A spring at the ``"left"`` or ``"right"`` end: rotational k [N m/rad], or with
        ``translation`` on the deflection (beam w, bar u) k [N/m].  It replaces a fixity of
        that DOF (a clamp or a pin that gives)."""
        self.end_springs.append((side, float(k), bool(translation)))

    # -- the elements -------------------------------------------------------------------
    def discretisation(self) -> "Discretisation":
        model = self.model
        L = model.element_length
        beam = model.kind == "beam"
        E = model.youngs_modulus
        rigidity = E * (model.inertia if beam else model.area)
        params, shear_g = self._stiffness(rigidity)
        mass = self._mass(E)
        extra = self._extra()
        constrained = set(constrained_dofs(model).tolist())
        nodal = self.nodal_springs()
        for dof, _ in nodal:
            constrained.discard(dof)  # a support that gives: the spring replaces the fixity
        scale = rigidity / (model.mass_per_length * model.length ** (4 if beam else 2))
        return Discretisation(kind=model.kind, nodes=model.nodes, element_length=L,
                              stiffness_params=params, mass=mass, extra_stiffness=extra,
                              nodal_stiffness=tuple(nodal),
                              constrained=np.array(sorted(constrained), dtype=int),
                              eigenvalue_scale=scale, shear_g=shear_g)

    def nodal_springs(self) -> list:
        """``(dof, k)`` of the end springs (each frees the DOF it is on)."""
        n, beam = self.model.elements, self.model.kind == "beam"
        nodal = []
        for side, k, translation in self.end_springs:
            node = 0 if side == "left" else n
            dof = (2 * node if beam else node) if translation else 2 * node + 1
            nodal.append((dof, k))
        return nodal

    def element_matrices(self, elements: np.ndarray) -> tuple[np.ndarray, ...]:
        """Generic stiffness, extra stiffness terms and mass of the ``elements`` (sorted
        indices) in physical DOFs, (len, n, n) each: the numbers :meth:`discretisation`
        gives them, without building the others (a fit's Jacobian differences the
        elements one effect changes, :func:`local_difference`).  Not for a shear beam (its
        g couples the sensors' reading to the elements)."""
        if self.shear_rigidity is not None:
            raise ValueError("element_matrices: a shear beam's elements are built whole")
        model = self.model
        E = model.youngs_modulus
        rigidity = E * (model.inertia if model.kind == "beam" else model.area)
        params, _ = self._stiffness(rigidity, elements)
        return (stiffness_elements(model.kind, params, model.element_length),
                self._extra(elements), self._mass(E, elements))

    def footprint(self) -> np.ndarray | None:
        """The elements this builder's effects change, sorted (their nodal springs aside),
        or None when they change every element (a factor without support, an element term,
        shear)."""
        n, L = self.model.elements, self.model.element_length
        if self.element_terms or self.shear_rigidity is not None:
            return None
        out = []
        for f in (*self.rigidity, *self.mass):
            if f.support is None:
                return None
            out.append(np.arange(*_support_range(f.support, L, n)))
        out += [[self._shape_at(x)[0]] for x, _ in (*self.point_stiffness, *self.point_masses,
                                                     *self.point_inertias)]
        return np.unique(np.concatenate(out)).astype(int) if out else np.zeros(0, dtype=int)

    def _extra(self, only=None) -> np.ndarray:
        """Element stiffness terms outside the generic family (element terms, point
        springs), physical DOFs; ``only``: of those elements."""
        model = self.model
        n, L = model.elements, model.element_length
        beam = model.kind == "beam"
        size = 4 if beam else 2
        place = _places(n, only)
        extra = np.zeros((n if only is None else len(only), size, size))
        tt = np.outer(*(2 * [el.beam_dof_scaling(L)])) if beam else np.ones((2, 2))
        for term in self.element_terms:
            extra = extra + term(L) * tt
        for x, k in self.point_stiffness:
            e, shape = self._shape_at(x)
            if place[e] >= 0:
                extra[place[e]] += k * np.outer(shape, shape)
        return extra

    def _shape_at(self, x):
        """Element index and shape functions (physical DOFs) at position x."""
        n, L = self.model.elements, self.model.element_length
        e = min(int(x // L), n - 1)
        xi = x / L - e
        if self.model.kind == "beam":
            return e, el.hermite(xi) * el.beam_dof_scaling(L)
        return e, el.linear(xi)

    def _slope_at(self, x):
        """Element index and the slope's shape functions (physical DOFs) at position x of a
        beam: at a node, its rotation DOF alone."""
        n, L = self.model.elements, self.model.element_length
        e = min(int(x // L), n - 1)
        return e, el.hermite_d1(x / L - e) * el.beam_dof_scaling(L) / L

    def _stiffness(self, rigidity: float, only=None) -> dict:
        """Generic stiffness parameters per element (``only``: of those elements) and the
        elements' Timoshenko g (None: Euler–Bernoulli)."""
        model = self.model
        n, L = model.elements, model.element_length
        if model.kind == "bar":
            k = np.full(n, rigidity)
            for elements, _, w, x in _quadrature(model, self.rigidity, only):
                k[elements] = L / np.sum(w / (rigidity * _product(self.rigidity, x)), axis=-1)
            return {"k": k if only is None else k[only]}, None
        out = {k: np.full(n, v) for k, v in el.euler_bernoulli_stiffness(rigidity).items()}
        for elements, s, w, x in _quadrature(model, self.rigidity, only):
            c = w / (rigidity * _product(self.rigidity, x))
            k_ww, k_wt, k_tt = el.flexibility_parameters(s, c, L)
            out["k_ww"][elements], out["k_wt"][elements], out["k_tt"][elements] = (
                k_ww, k_wt, k_tt)
        if only is not None:
            out = {k: v[only] for k, v in out.items()}
        g = None
        if self.shear_rigidity is not None:
            g = el.shear_parameter(out["k_ww"] / 12.0, self.shear_rigidity, L)
            out = el.timoshenko_correction(out, g)
        return out, g

    def _mass(self, E: float, only=None) -> np.ndarray:
        """Element masses in physical DOFs, point masses included (``only``: of those
        elements)."""
        model = self.model
        n, L = model.elements, model.element_length
        rho_a = model.mass_per_length
        shape, scaling = (el.linear, np.ones(2)) if model.kind == "bar" else (
            el.hermite, el.beam_dof_scaling(L))
        mass = _uniform_mass(model.kind, n, L, rho_a, model.mass_model, E, model.inertia,
                             model.rho, self.shear_rigidity)
        mass = mass.copy() if only is None else mass[only]
        place = _places(n, only)
        for elements, s, w, x in _quadrature(model, self.mass, only):
            N = shape(s / L) * scaling
            change = rho_a * w * (_product(self.mass, x) - 1.0)
            mass[place[elements]] += np.swapaxes(N, -1, -2) @ (change[..., None] * N)
        for x, m in self.point_masses:
            e, shape_at = self._shape_at(x)
            if place[e] >= 0:
                mass[place[e]] += m * np.outer(shape_at, shape_at)
        for x, J in self.point_inertias:
            e, slope = self._slope_at(x)
            if place[e] >= 0:
                mass[place[e]] += J * np.outer(slope, slope)
        return mass


def _places(n: int, only) -> np.ndarray:
    """Where each of n elements sits among ``only`` (all of them: itself; -1: not there)."""
    if only is None:
        return np.arange(n)
    place = np.full(n, -1)
    place[only] = np.arange(len(only))
    return place


def _support_range(support, L: float, n: int) -> tuple[int, int]:
    """The elements [lo, hi) that a factor's support (x0, x1) reaches, even in part."""
    return max(int(np.floor(support[0] / L)), 0), min(int(np.ceil(support[1] / L)), n)


def stiffness_elements(kind: str, params: dict, L) -> np.ndarray:
    """Generic element stiffness (eq. 2, eq. 11) in physical DOFs, (n_elements, n, n); ``L``
    the elements' length, or one length an element (a frame's members)."""
    if kind == "bar":
        return el.generic_bar_stiffness(params["k"], L)
    t = el.beam_dof_scaling(L)
    ks = el.generic_beam_stiffness(params["k_ww"], params["k_wt"], params["k_tt"])
    if np.ndim(L):
        return ks * (t[:, :, None] * t[:, None, :]) / np.asarray(L)[:, None, None] ** 3
    return ks * (t[:, None] * t[None, :]) / L**3


@lru_cache(maxsize=64)
def _uniform_mass(kind, n, L, rho_a, mass_model, E, inertia, rho, shear_rigidity):
    """The element masses of a uniform beam or bar (read-only; kept: a fit's effects that
    leave the mass alone rebuild the model at every evaluation)."""
    mass = _uniform_mass_of(kind, n, L, rho_a, mass_model, E, inertia, rho, shear_rigidity)
    mass.flags.writeable = False
    return mass


def _uniform_mass_of(kind, n, L, rho_a, mass_model, E, inertia, rho, shear_rigidity):
    if kind == "bar":
        beta = el.BAR_MASS_BETA[mass_model]
        return el.generic_bar_mass(np.full(n, rho_a), L, np.full(n, beta))
    if shear_rigidity is not None:
        ei = E * inertia
        g = el.shear_parameter(ei, shear_rigidity, L)
        _, mass_params = el.timoshenko_parameters(ei, shear_rigidity, L)
    else:
        g = 0.0
        mass_params = {"consistent": el.CONSISTENT_BEAM_MASS,
                       "higher_order": el.HIGHER_ORDER_BEAM_MASS}[mass_model]
    scaled = rho_a * L * el.symmetric_beam_mass(**{k: np.full(n, v)
                                                   for k, v in mass_params.items()})
    if shear_rigidity is not None:
        scaled = scaled + el.timoshenko_rotary_inertia(np.full(n, rho * inertia), L,
                                                       np.full(n, g))
    scaling = el.beam_dof_scaling(L)
    return scaled * np.outer(scaling, scaling)


def _product(factors, x):
    out = np.ones_like(x)
    for f in factors:
        out = out * f.fn(x)
    return out


def _quadrature(model: Model, factors, only=None):
    """Quadrature on the elements the factors change (``only``: of those among the given
    ones): yields ``(elements, s, w, x)`` with local coordinates s, weights w and positions
    x (last axis: points); elements next to a breakpoint one at a time (graded points), the
    others together (Gauss)."""
    if not factors:
        return
    n, L = model.elements, model.element_length
    affected = np.zeros(n, dtype=bool)
    for f in factors:
        if f.support is None:
            affected[:] = True
        else:
            affected[slice(*_support_range(f.support, L, n))] = True
    if only is not None:
        affected &= _places(n, only) >= 0
    # only an element with a kink inside needs graded points: away from it the factor is
    # smooth (a crack's exp(-|x - x_c|/ℓ) over an element of 3ℓ: Gauss-8 error ~1e-15)
    near = np.zeros(n, dtype=bool)
    kinks = [(b, f.refine_scale) for f in factors for b in f.breakpoints]
    x0 = np.arange(n) * L
    for b, _ in kinks:
        near |= (x0 < b) & (b < x0 + L)
    near &= affected
    plain = np.flatnonzero(affected & ~near)
    if plain.size:
        g, w = el._gauss_legendre(GAUSS_ORDER)
        s = 0.5 * L * (g + 1.0)
        yield plain, np.broadcast_to(s, (plain.size, s.size)), np.broadcast_to(
            0.5 * L * w, (plain.size, s.size)), x0[plain, None] + s[None, :]
    for e in np.flatnonzero(near):
        points = [b for b, _ in kinks if x0[e] < b < x0[e] + L]
        scales = [r for b, r in kinks if r and b in points]
        x, w = _element_quadrature(float(x0[e]), float(x0[e] + L), tuple(points),
                                   min(scales) if scales else None)
        yield np.array([e]), (x - x0[e])[None, :], w[None, :], x[None, :]


@lru_cache(maxsize=1024)
def _element_quadrature(x0: float, x1: float, points: tuple, scale):
    """:func:`~gfe_opt.elements.element_quadrature` kept (read-only): an element's graded
    points recur in a fit (its stiffness and its mass, every model of a difference, every
    evaluation that leaves the kink where it was)."""
    x, w = el.element_quadrature(x0, x1, points, scale)
    x.flags.writeable = w.flags.writeable = False
    return x, w


def builder(model: Model) -> Builder:
    """A :class:`Builder` told by each effect of ``model`` what it changes."""
    from .effects import effect_type

    build = Builder(model)
    for effect in model.effects:
        effect_type(effect.name).contribute(model, effect.parameters, build)
    return build


@lru_cache(maxsize=256)
def _rigid_motions(kind: str, nodes: bytes, constrained: bytes):
    """The rigid motions w = a + b x, θ = b (bar: u = a) of a line's nodes (float64 bytes)
    as columns of ``basis``, and ``null``, the combinations that vanish at the constrained
    DOFs (int64 bytes); read-only, one pair for every discretisation of a mesh and its
    supports (a fit builds hundreds)."""
    import scipy.linalg as sla

    x = np.frombuffer(nodes, dtype=float)
    n_dof = (2 if kind == "beam" else 1) * len(x)
    if kind == "beam":
        basis = np.zeros((n_dof, 2))
        basis[0::2, 0] = 1.0
        basis[0::2, 1], basis[1::2, 1] = x - x[0], 1.0
    else:
        basis = np.ones((n_dof, 1))
    fixed = basis[np.frombuffer(constrained, dtype=np.int64)]
    null = sla.null_space(fixed) if fixed.size else np.eye(basis.shape[1])
    for a in (basis, null):
        a.flags.writeable = False
    return basis, null


@lru_cache(maxsize=256)
def free_dofs(n_dof: int, constrained: bytes) -> np.ndarray:
    """The DOFs of ``range(n_dof)`` not in ``constrained`` (int64 bytes), read-only: one
    array for every discretisation of a mesh and its supports (a fit builds hundreds)."""
    free = np.setdiff1d(np.arange(n_dof), np.frombuffer(constrained, dtype=np.int64))
    free.flags.writeable = False
    return free


#: above this many DOFs a local difference (:func:`local_difference`) is sparse
DENSE_DIFFERENCE_DOFS = 500


def local_difference(models, weights, index: int):
    """Σ wᵢ K(modelsᵢ) and Σ wᵢ M(modelsᵢ) (all DOFs) of models that differ only in their
    effect ``index`` (a fit's Jacobian differencing one variable's matrices), summed on the
    elements that effect changes in any of them and its nodal springs: elsewhere the terms
    are the same numbers and cancel exactly.  Dense up to :data:`DENSE_DIFFERENCE_DOFS`,
    else sparse.  None where the difference is not local: an effect on every element (a
    uniform factor, an element term, E) or a shear beam (its g couples the sensors' reading
    to the elements).  Plane frames: :func:`gfe_opt.frame.local_difference` (sparse)."""
    if any(m.kind == "frame" for m in models):
        if not all(m.kind == "frame" for m in models):
            return None
        from .frame import local_difference as frame_difference

        return frame_difference(models, weights, index)
    if any(m.kind not in ("beam", "bar") for m in models) or len(
            {m.youngs_modulus for m in models}) > 1:
        return None
    from .effects import effect_type

    builds, parts = [], []
    for m in models:
        effect = m.effects[index]
        alone = Builder(m)
        effect_type(effect.name).contribute(m, effect.parameters, alone)
        part = alone.footprint()
        if part is None:
            return None
        build = builder(m)
        if build.shear_rigidity is not None:
            return None
        builds.append(build)
        parts.append(part)
    elements = np.unique(np.concatenate(parts)).astype(int)
    first = models[0]
    per = 2 if first.kind == "beam" else 1
    n_dof = per * (first.elements + 1)
    size = 2 * per
    # Σ wᵢ (Aᵢ − A_last) (the weights of a derivative sum to zero), each part apart: a
    # part the effect leaves alone (the beam's own stiffness under a point spring, a spring
    # on a held DOF) is then exactly zero instead of rounding
    def weighted(values):
        return weighted_difference(values, weights)

    parts = [build.element_matrices(elements) for build in builds] if elements.size else []
    dK, dM = ((weighted([p[0] for p in parts]) + weighted([p[1] for p in parts]),
               weighted([p[2] for p in parts])) if parts else
              (np.zeros((0, size, size)), np.zeros((0, size, size))))
    springs = [dict(build.nodal_springs()) for build in builds]
    nodal = {dof: weighted([s.get(dof, 0.0) for s in springs])
             for dof in sorted(set().union(*springs))}
    dofs = elements[:, None] * per + np.arange(size)[None, :]
    rows = np.concatenate([np.repeat(dofs, size, axis=1).ravel(), list(nodal)]).astype(int)
    cols = np.concatenate([np.tile(dofs, (1, size)).ravel(), list(nodal)]).astype(int)
    values = np.concatenate([dK.ravel(), list(nodal.values())])
    mass_values = np.concatenate([dM.ravel(), np.zeros(len(nodal))])
    if n_dof <= DENSE_DIFFERENCE_DOFS:
        flat = rows * n_dof + cols
        return tuple(np.bincount(flat, weights=v, minlength=n_dof * n_dof).reshape(n_dof, n_dof)
                     for v in (values, mass_values))
    return tuple(sp.csr_matrix((v, (rows, cols)), shape=(n_dof, n_dof))
                 for v in (values, mass_values))


def weighted_difference(values, weights):
    """Σ wᵢ (vᵢ − v_last) of ``values`` (numbers, arrays or sparse matrices) with a
    derivative's ``weights``, which sum to zero: Σ wᵢ vᵢ with each term taken against the
    last, so that a part every value shares cancels exactly (:func:`local_difference`,
    :func:`gfe_opt.frame.local_difference`)."""
    out = weights[0] * (values[0] - values[-1])
    for w, v in zip(weights[1:-1], values[1:-1]):
        out = out + w * (v - values[-1])
    return out


def discretise(model: Model) -> Discretisation:
    """Element data of ``model`` including its effects (a plane frame:
    :class:`~gfe_opt.frame.FrameDiscretisation`)."""
    if model.kind == "frame":
        from .frame import FrameDiscretisation

        return FrameDiscretisation(model)
    return builder(model).discretisation()


def rigidity_function(model: Model):
    """EI(x) (bar: EA(x)) of the model with its effects, as a vectorised function, and the
    breakpoints of its factors (for references that integrate it another way)."""
    build = builder(model)
    base = model.youngs_modulus * (model.inertia if model.kind == "beam" else model.area)
    return (lambda x: base * _product(build.rigidity, np.asarray(x, float)),
            tuple(b for f in build.rigidity for b in f.breakpoints))

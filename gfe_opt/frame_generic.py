r"""The paper's generic-element update on a plane frame, member by member (issue 24).

A member is the paper's generic beam element (bending: k_ww, k_wθ, k_θθ a element, eq. 11)
together with its generic bar element (axial: k = EA a element, eq. 2), rotated into the
frame's axes.  Along each member the bending elements are parameterised by the member's own
nodal stiffness k_i and slope ∂k_i/∂x (eq. 13) and the axial ones by its nodal EA_i (eq. 7
with c₁ = c₂ = ½): inter-element equilibrium along the member built in; a member's values at
a joint are its own, not its neighbour's.  What the update does not touch is held as the
model has it: the geometric stiffness of an axial load, a foundation, the springs at joints,
supports and points, the masses.  So

.. math:: K(q) = K_{\text{rest}} + \sum_e T_e^T \big[H^T P_e(q) H / L^3 \oplus
          k_e(q) / L \, [[1, -1], [-1, 1]]\big] T_e,

affine in q, and the equation error, its expansion of the measured shapes, its
strain-energy weighting, energy balance, regularisation and feasibility conditions
(k_ww k_θθ > k_wθ², k > 0) are the beam's (:func:`gfe_opt.updating.update_generic`), on the
frame's DOFs.

:class:`FrameGeneric` is the frame behind the interface that update works on;
:func:`update_frame_generic` runs it; :func:`member_ratios` reads the result as each
member's k_i / k_i0 (bending) and EA_i / EA_i0 (axial) along it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import lsqr, splu

from . import elements as el
from .assembly import stiffness_elements
from .frame import (
    FrameDiscretisation,
    FrameModel,
    _assemble,
    frame_matrices,
    frame_mesh,
    member_elements,
    rotations,
)
from .parameterisation import (
    BEAM_KEYS,
    Parameterisation,
    bar_parameterisation,
    beam_parameterisation,
)

_BEND = [1, 2, 4, 5]
_AXIAL = [0, 3]
#: the generic parameters of a frame's element: bending (eq. 11), then axial (eq. 2, EA)
FRAME_KEYS = (*BEAM_KEYS, "k")


class FrameGeneric:
    """A frame's generic bending parameters and the rest of its matrices, behind the
    interface of :class:`~gfe_opt.assembly.Discretisation` that the generic update uses
    (``kind``, ``free``, ``n_dof``, ``n_elements``, ``stiffness_params``,
    :meth:`global_matrices`, :meth:`element_dofs`, :meth:`stiffness_elements`,
    :meth:`fixed_stiffness`, :meth:`element_strain_energy`, :meth:`with_stiffness`), and
    :meth:`observation`, the sensors' reading through ``model`` and ``mesh``."""

    kind = "frame"
    observation = FrameDiscretisation.observation

    def __init__(self, model: FrameModel):
        self.model = model
        self.mesh = frame_mesh(model)
        members = member_elements(model)
        p = np.concatenate([m.bending for m in members])
        self.stiffness_params = {k: p[:, i].copy() for i, k in enumerate(BEAM_KEYS)}
        self.stiffness_params["k"] = np.concatenate([m.axial for m in members])
        self.n_elements = p.shape[0]
        self.n_dof = self.mesh.n_dof
        self.constrained = self.mesh.constrained
        self.free = np.setdiff1d(np.arange(self.n_dof), self.constrained)
        self.element_length = self.mesh.element_length
        L, n = self.element_length, self.n_elements
        T = rotations(self.mesh.cosines)
        Tt = np.swapaxes(T, 1, 2)
        self._units = {}   # each generic parameter's unit element, as the members' elements
        for key in BEAM_KEYS:
            local = np.zeros((n, 6, 6))
            local[np.ix_(range(n), _BEND, _BEND)] = stiffness_elements(
                "beam", {k: np.full(n, float(k == key)) for k in BEAM_KEYS}, L)
            self._units[key] = Tt @ local @ T
        local = np.zeros((n, 6, 6))
        local[np.ix_(range(n), _AXIAL, _AXIAL)] = el.generic_bar_stiffness(np.ones(n), L)
        self._units["k"] = Tt @ local @ T
        K, self._M = frame_matrices(model, self.mesh)
        self._rest = (K - self._generic(self.stiffness_params)).tocsr()

    def _generic(self, params) -> sp.csr_matrix:
        """The assembled generic part of K (bending and axial) for ``params``."""
        mesh = self.mesh
        values = self.stiffness_elements(params)
        pad = 4 * len(mesh.springs) + len(mesh.grounded)
        return _assemble(mesh, "K", np.concatenate([values.ravel(), np.zeros(pad)]))

    # -- the interface of the generic update --------------------------------------------
    def element_dofs(self) -> np.ndarray:
        return self.mesh.element_dofs

    def stiffness_elements(self, params=None) -> np.ndarray:
        """(n_elements, 6, 6) generic stiffness (bending and axial) in global axes."""
        params = self.stiffness_params if params is None else params
        return sum(np.asarray(params[k], float)[:, None, None] * self._units[k]
                   for k in FRAME_KEYS)

    def fixed_stiffness(self) -> sp.csr_matrix:
        """What the update holds: K without the members' generic elements (all DOFs)."""
        return self._rest

    def global_matrices(self, params=None):
        """(K, M) over all DOFs with the generic ``params`` (None: this one's)."""
        params = self.stiffness_params if params is None else params
        return (self._rest + self._generic(params)).tocsr(), self._M

    def element_strain_energy(self, shapes, params=None) -> np.ndarray:
        """Twice the generic strain energy (bending and axial) of each element,
        (n_elements, n_modes)."""
        return sum(self.key_energy(shapes, params).values())

    def key_energy(self, shapes, params=None) -> dict:
        """Twice each generic parameter's share of each element's strain energy:
        {key: (n_elements, n_modes)}."""
        params = self.stiffness_params if params is None else params
        u = np.asarray(shapes, float)[self.mesh.element_dofs]     # (n_el, 6, m)
        return {k: np.asarray(params[k], float)[:, None]
                * np.einsum("eim,eij,ejm->em", u, self._units[k], u) for k in FRAME_KEYS}

    def parameter_energy(self, par, shapes) -> np.ndarray:
        """Each parameter's share of the strain energy of ``shapes`` (summed over the
        modes): the bending energy for a bending parameter, the axial for an axial one."""
        e = self.key_energy(shapes)
        bending = np.abs(sum(e[k] for k in BEAM_KEYS)).sum(axis=1)
        axial = np.abs(e["k"]).sum(axis=1)
        return np.abs(par.matrix).T @ np.concatenate([bending, bending, bending, axial])

    def dof_energy_share(self, shapes) -> np.ndarray:
        """(n_dof, m): the strain energy of the elements at each DOF (half of each),
        normalised by its mean over the DOFs elements reach."""
        e = np.abs(self.element_strain_energy(shapes))
        share = np.zeros((self.n_dof, e.shape[1]))
        np.add.at(share, self.mesh.element_dofs, 0.5 * e[:, None, :])
        reached = np.zeros(self.n_dof, dtype=bool)
        reached[self.mesh.element_dofs.ravel()] = True
        return share / np.maximum(share[reached].mean(axis=0), 1e-300)

    def parameter_scale(self, par: "FrameParameterisation") -> np.ndarray:
        """Each parameter's scale: its member's EI (k_i), EI / element length (∂k/∂x), EA
        (EA_i)."""
        out = np.empty(par.n_params)
        bending = self.stiffness_params["k_ww"] / 12.0
        axial = self.stiffness_params["k"]
        for (lo, hi), L, (a, b) in zip(par.slices, par.lengths, par.element_ranges):
            n = (hi - lo) // 3
            ei, ea = float(np.mean(bending[a:b])), float(np.mean(axial[a:b]))
            out[lo:lo + n], out[lo + n:lo + 2 * n], out[lo + 2 * n:hi] = ei, ei / L, ea
        return out

    def with_stiffness(self, params) -> "FrameGeneric":
        out = copy.copy(self)
        out.stiffness_params = {k: np.asarray(v, float) for k, v in params.items()}
        return out


@dataclass(frozen=True)
class FrameParameterisation(Parameterisation):
    """Eq. 13 and eq. 7 on each member: q is, member by member, its nodal k_0 … k_n, then
    ∂k/∂x at the same nodes, then its nodal EA_0 … EA_n; ``slices`` each member's range of
    q, ``element_ranges`` its elements', ``lengths`` its element length, ``positions`` its
    nodes along it [m]."""

    members: tuple = ()
    slices: tuple = ()
    element_ranges: tuple = ()
    lengths: tuple = ()
    positions: tuple = ()

    def fit(self, params: dict) -> np.ndarray:
        """The q whose element parameters are closest to ``params``: the bending columns
        by least squares (full rank), the axial ones by the least-norm solution of their
        own rows (eq. 7's nodal values alternating about the elements' are one structure),
        each block on its own scale."""
        n_el = self.n_elements
        axial = np.zeros(self.n_params, dtype=bool)
        for lo, hi in self.slices:
            axial[lo + 2 * (hi - lo) // 3:hi] = True
        A = self.matrix.tocsc()
        q = np.zeros(self.n_params)
        bend = A[:3 * n_el][:, ~axial]
        target = np.concatenate([params[k] for k in BEAM_KEYS])
        q[~axial] = splu((bend.T @ bend).tocsc()).solve(bend.T @ target)
        k = np.asarray(params["k"], float)
        scale = float(np.max(np.abs(k))) or 1.0
        q[axial] = scale * lsqr(A[3 * n_el:][:, axial], k / scale, atol=1e-15, btol=1e-15,
                                iter_lim=10 * int(axial.sum()))[0]
        return q


def frame_parameterisation(model: FrameModel) -> FrameParameterisation:
    """The nodal parameterisations (bending eq. 13, axial eq. 7) of every member, stacked:
    rows the frame's element parameters ``[k_ww, k_wθ, k_θθ, k]`` in element order, columns
    member by member."""
    labels, slices, ranges, lengths, positions = [], [], [], [], []
    n_total = model.n_elements
    start_q = start_e = 0
    rows, cols, vals = [], [], []
    for member in model.members:
        n = member.elements
        length = model.member_length(member)
        L = length / n
        A = beam_parameterisation("nodal", n, L).matrix.tocoo()
        key, local = np.divmod(A.row, n)
        B = bar_parameterisation("nodal", n).matrix.tocoo()
        rows += [key * n_total + start_e + local, 3 * n_total + start_e + B.row]
        cols += [A.col + start_q, B.col + start_q + 2 * (n + 1)]
        vals += [A.data, B.data]
        labels += [f"{member.id}:k[{i}]" for i in range(n + 1)]
        labels += [f"{member.id}:dk/dx[{i}]" for i in range(n + 1)]
        labels += [f"{member.id}:EA[{i}]" for i in range(n + 1)]
        slices.append((start_q, start_q + 3 * (n + 1)))
        ranges.append((start_e, start_e + n))
        lengths.append(L)
        positions.append(np.linspace(0.0, length, n + 1))
        start_q += 3 * (n + 1)
        start_e += n
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                   np.concatenate(cols))),
                           shape=(4 * n_total, start_q))
    return FrameParameterisation("nodal", matrix, tuple(labels), FRAME_KEYS,
                                 members=tuple(m.id for m in model.members),
                                 slices=tuple(slices), element_ranges=tuple(ranges),
                                 lengths=tuple(lengths), positions=tuple(positions))


#: the residual weighting of a frame's generic update (:func:`gfe_opt.updating.update_generic`):
#: the paper's rows; ``scripts/bench_frame_generic.py --weighting energy`` measures the other
WEIGHTING = "rows"


def update_frame_generic(model: FrameModel, measured, *, noise: float, **options):
    """The generic update (:func:`~gfe_opt.updating.update_generic`, ``expand``, the row
    weighting) of a frame's members; ``noise`` the relative shape noise."""
    from .updating import update_generic

    disc = FrameGeneric(model)
    return update_generic(disc, measured, parameterisation=frame_parameterisation(model),
                          noise=noise, weighting=WEIGHTING, **options)


def member_ratios(result, axial: bool = False) -> dict:
    """Each member's nodal k_i / k_i0 of an update's result, or with ``axial`` each of its
    elements' EA / EA0 at the element's centre (eq. 7 averages neighbouring nodal EA_i, so
    nodal values alternating about the element's are one structure: the elements' are what
    the data determine): {member: (positions along it, ratio)}."""
    par = result.parameterisation
    out = {}
    if axial:
        k, k0 = (par.element_parameters(q)["k"] for q in (result.q, result.q0))
    for member, (lo, hi), x, (a, b) in zip(par.members, par.slices, par.positions,
                                           par.element_ranges):
        n = (hi - lo) // 3
        out[member] = ((0.5 * (x[1:] + x[:-1]), k[a:b] / k0[a:b]) if axial else
                       (x, result.q[lo:lo + n] / result.q0[lo:lo + n]))
    return out

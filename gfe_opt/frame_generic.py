r"""The paper's generic-element update on a plane frame, member by member (issue 24).

Every member's bending elements are the generic beam element of eq. 11 (k_ww, k_wθ, k_θθ a
element), parameterised along the member by its own nodal stiffness k_i and slope ∂k_i/∂x
(eq. 13: inter-element equilibrium along the member built in; a member's k at a joint is
its own, not its neighbour's). What the update does not touch is held as the model has it:
the members' axial elements, the geometric stiffness of an axial load, a foundation, the
springs at joints and supports and at points, the masses. So

.. math:: K(q) = K_{\text{rest}} + \sum_e T_e^T \big[H^T P_e(q) H / L^3\big] T_e,

affine in q, and the equation error, its expansion of the measured shapes, its
strain-energy weighting, energy balance, regularisation and feasibility conditions
(k_ww k_θθ > k_wθ²) are the beam's (:func:`gfe_opt.updating.update_generic`), on the
frame's DOFs.

:class:`FrameGeneric` is the frame behind the interface that update works on;
:func:`update_frame_generic` runs it; :func:`member_ratios` reads the result as each
member's k_i / k_i0 along it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .frame import FrameModel, _assemble, frame_matrices, frame_mesh, member_elements, rotations
from .parameterisation import BEAM_KEYS, Parameterisation, beam_parameterisation

#: the unit P of each generic bending parameter (k_ww, k_wθ, k_θθ)
_UNIT_P = {"k_ww": np.array([[1.0, 0.0], [0.0, 0.0]]),
           "k_wt": np.array([[0.0, 1.0], [1.0, 0.0]]),
           "k_tt": np.array([[0.0, 0.0], [0.0, 1.0]])}
_BEND = [1, 2, 4, 5]


class FrameGeneric:
    """A frame's generic bending parameters and the rest of its matrices, behind the
    interface of :class:`~gfe_opt.assembly.Discretisation` that the generic update uses
    (``kind``, ``free``, ``n_dof``, ``n_elements``, ``stiffness_params``,
    :meth:`global_matrices`, :meth:`element_dofs`, :meth:`stiffness_elements`,
    :meth:`fixed_stiffness`, :meth:`element_strain_energy`, :meth:`with_stiffness`), and
    ``model``/``mesh`` for the sensors' reading."""

    kind = "frame"

    def __init__(self, model: FrameModel):
        self.model = model
        self.mesh = frame_mesh(model)
        members = member_elements(model)
        p = np.concatenate([m.bending for m in members])
        self.stiffness_params = {k: p[:, i].copy() for i, k in enumerate(BEAM_KEYS)}
        self.n_elements = p.shape[0]
        self.n_dof = self.mesh.n_dof
        self.constrained = self.mesh.constrained
        self.free = np.setdiff1d(np.arange(self.n_dof), self.constrained)
        self.element_length = self.mesh.element_length
        L = self.element_length
        H = el.BEAM_DEFORMATION_H
        scaling = el.beam_dof_scaling(L)
        T = rotations(self.mesh.cosines)
        Tt = np.swapaxes(T, 1, 2)
        self._units = {}
        for key, P in _UNIT_P.items():
            local = np.zeros((self.n_elements, 6, 6))
            scaled = (H.T @ P @ H)[None] / L[:, None, None] ** 3
            local[np.ix_(range(self.n_elements), _BEND, _BEND)] = \
                scaled * scaling[:, :, None] * scaling[:, None, :]
            self._units[key] = Tt @ local @ T
        K, self._M = frame_matrices(model, self.mesh)
        self._rest = (K - self._bending(self.stiffness_params)).tocsr()

    def _bending(self, params) -> sp.csr_matrix:
        """The assembled bending part of K for generic ``params``."""
        mesh = self.mesh
        values = self.stiffness_elements(params)
        pad = 4 * len(mesh.springs) + len(mesh.grounded)
        return _assemble(mesh, "K", np.concatenate([values.ravel(), np.zeros(pad)]))

    # -- the interface of the generic update --------------------------------------------
    def element_dofs(self) -> np.ndarray:
        return self.mesh.element_dofs

    def stiffness_elements(self, params=None) -> np.ndarray:
        """(n_elements, 6, 6) generic bending stiffness in global axes."""
        params = self.stiffness_params if params is None else params
        return sum(np.asarray(params[k], float)[:, None, None] * self._units[k]
                   for k in BEAM_KEYS)

    def fixed_stiffness(self) -> sp.csr_matrix:
        """What the update holds: K without the members' generic bending (all DOFs)."""
        return self._rest

    def global_matrices(self, params=None):
        """(K, M) over all DOFs with the generic bending ``params`` (None: this one's)."""
        params = self.stiffness_params if params is None else params
        return (self._rest + self._bending(params)).tocsr(), self._M

    def element_strain_energy(self, shapes, params=None) -> np.ndarray:
        """Twice the generic bending strain energy of each element, (n_elements, n_modes)."""
        params = self.stiffness_params if params is None else params
        u = np.asarray(shapes, float)[self.mesh.element_dofs]     # (n_el, 6, m)
        return np.einsum("eim,eij,ejm->em", u, self.stiffness_elements(params), u)

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
        """Each parameter's scale: its member's EI (k_i), EI / element length (∂k/∂x)."""
        out = np.empty(par.n_params)
        for (lo, hi), L, ei in zip(par.slices, par.lengths, self.member_rigidity(par)):
            n = (hi - lo) // 2
            out[lo:lo + n], out[lo + n:hi] = ei, ei / L
        return out

    def member_rigidity(self, par: "FrameParameterisation") -> list[float]:
        """Each member's mean EI (k_ww / 12 over its elements) in the model."""
        k = self.stiffness_params["k_ww"] / 12.0
        return [float(np.mean(k[a:b])) for a, b in par.element_ranges]

    def with_stiffness(self, params) -> "FrameGeneric":
        out = copy.copy(self)
        out.stiffness_params = {k: np.asarray(v, float) for k, v in params.items()}
        return out


@dataclass(frozen=True)
class FrameParameterisation(Parameterisation):
    """Eq. 13 on each member: q is, member by member, its nodal k_0 … k_n then ∂k/∂x at
    the same nodes; ``slices`` each member's range of q, ``element_ranges`` its elements',
    ``lengths`` its element length, ``positions`` its nodes along it [m]."""

    members: tuple = ()
    slices: tuple = ()
    element_ranges: tuple = ()
    lengths: tuple = ()
    positions: tuple = ()


def frame_parameterisation(model: FrameModel) -> FrameParameterisation:
    """The nodal parameterisation (eq. 13) of every member, stacked: rows the frame's
    element parameters ``[k_ww, k_wθ, k_θθ]`` in element order, columns member by member."""
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
        rows.append(key * n_total + start_e + local)
        cols.append(A.col + start_q)
        vals.append(A.data)
        labels += [f"{member.id}:k[{i}]" for i in range(n + 1)]
        labels += [f"{member.id}:dk/dx[{i}]" for i in range(n + 1)]
        slices.append((start_q, start_q + 2 * (n + 1)))
        ranges.append((start_e, start_e + n))
        lengths.append(L)
        positions.append(np.linspace(0.0, length, n + 1))
        start_q += 2 * (n + 1)
        start_e += n
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                   np.concatenate(cols))),
                           shape=(3 * n_total, start_q))
    return FrameParameterisation("nodal", matrix, tuple(labels), BEAM_KEYS,
                                 members=tuple(m.id for m in model.members),
                                 slices=tuple(slices), element_ranges=tuple(ranges),
                                 lengths=tuple(lengths), positions=tuple(positions))


def update_frame_generic(model: FrameModel, measured, *, noise: float, **options):
    """The generic update (:func:`~gfe_opt.updating.update_generic`, ``expand``, the row
    weighting) of a frame's members; ``noise`` the relative shape noise."""
    from .updating import update_generic

    disc = FrameGeneric(model)
    return update_generic(disc, measured, parameterisation=frame_parameterisation(model),
                          noise=noise, weighting="rows", **options)


def member_ratios(result) -> dict:
    """Each member's nodal k_i / k_i0 of an update's result: {member: (positions, ratio)}."""
    par = result.parameterisation
    out = {}
    for member, (lo, hi), x in zip(par.members, par.slices, par.positions):
        n = (hi - lo) // 2
        out[member] = (x, result.q[lo:lo + n] / result.q0[lo:lo + n])
    return out

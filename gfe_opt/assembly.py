"""From a :class:`~gfe_opt.model.Model` to element and global (sparse) matrices.

The stiffness of every element is held as *generic parameters* (eq. 2 for a bar, eq. 11 for a
beam), so the updating engine can replace them; effects that a generic element cannot hold
(geometric stiffness of an axial load, a Winkler foundation, support springs) are kept apart
as extra terms.  Global DOFs are node-major: a beam node i has ``w`` at 2i and θ at 2i+1
(physical rotation in rad), a bar node i has ``u`` at i.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .model import Model


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

    @property
    def n_elements(self) -> int:
        return len(self.nodes) - 1

    @property
    def dofs_per_node(self) -> int:
        return 2 if self.kind == "beam" else 1

    @property
    def n_dof(self) -> int:
        return self.dofs_per_node * len(self.nodes)

    @property
    def free(self) -> np.ndarray:
        return np.setdiff1d(np.arange(self.n_dof), self.constrained)

    def element_dofs(self) -> np.ndarray:
        """(n_elements, 2 n) global DOF indices of each element."""
        n = self.dofs_per_node
        return np.arange(self.n_elements)[:, None] * n + np.arange(2 * n)[None, :]

    def stiffness_elements(self, params=None) -> np.ndarray:
        """Generic element stiffness in physical DOFs, (n_elements, n, n)."""
        params = self.stiffness_params if params is None else params
        L = self.element_length
        if self.kind == "bar":
            return el.generic_bar_stiffness(params["k"], L)
        t = el.beam_dof_scaling(L)
        ks = el.generic_beam_stiffness(params["k_ww"], params["k_wt"], params["k_tt"])
        return ks * (t[:, None] * t[None, :]) / L**3

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
        u = shapes[self.element_dofs()]
        energy = self.element_strain_energy(shapes, params).sum(axis=0)
        energy = energy + np.einsum("eim,eij,ejm->m", u, self.extra_stiffness, u)
        for dof, value in self.nodal_stiffness:
            energy = energy + value * shapes[dof] ** 2
        return energy

    def with_stiffness(self, params) -> "Discretisation":
        return replace(self, stiffness_params={k: np.asarray(v, float) for k, v in params.items()})

    def assemble_elements(self, matrices) -> sp.csr_matrix:
        """Sum element matrices (n_elements, n, n) into a global sparse matrix."""
        dofs = self.element_dofs()
        rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
        cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
        return sp.csr_matrix((np.asarray(matrices).ravel(), (rows, cols)),
                             shape=(self.n_dof, self.n_dof))

    def global_matrices(self, params=None) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Global (K, M) over all DOFs, boundary conditions not applied."""
        K = self.assemble_elements(self.stiffness_elements(params) + self.extra_stiffness)
        if self.nodal_stiffness:
            dof, val = zip(*self.nodal_stiffness)
            K = K + sp.csr_matrix((val, (dof, dof)), shape=K.shape)
        M = self.assemble_elements(self.mass)
        return K.tocsr(), M.tocsr()


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


def _mass_elements(model: Model, L: float) -> np.ndarray:
    n = model.elements
    rho_a = model.mass_per_length
    if model.kind == "bar":
        beta = el.BAR_MASS_BETA[model.mass_model]
        return el.generic_bar_mass(np.full(n, rho_a), L, np.full(n, beta))
    shear = model.effects_named("shear")
    if shear:
        g = el.shear_parameter(model.bending_rigidity, shear[0].parameters["shear_rigidity"], L)
        _, mass_params = el.timoshenko_parameters(model.bending_rigidity,
                                                  shear[0].parameters["shear_rigidity"], L)
    else:
        g = 0.0
        mass_params = {"consistent": el.CONSISTENT_BEAM_MASS,
                       "higher_order": el.HIGHER_ORDER_BEAM_MASS}[model.mass_model]
    scaled = rho_a * L * el.symmetric_beam_mass(**{k: np.full(n, v)
                                                   for k, v in mass_params.items()})
    if shear:
        scaled = scaled + el.timoshenko_rotary_inertia(
            np.full(n, model.rho * model.inertia), L, np.full(n, g))
    t = el.beam_dof_scaling(L)
    return scaled * (t[:, None] * t[None, :])


def slope_gram(L: float) -> np.ndarray:
    r""":math:`\int N' N'^T dx` of the Hermite element in scaled DOFs (geometric stiffness)."""
    return el.timoshenko_rotary_inertia(1.0, L, 0.0)


def crack_element_parameters(model: Model, element_stiffness) -> dict:
    """Generic parameters of every element of a cracked beam.

    EI(x) = EI Π_c Q_c(x) (Christides–Barr, eq. 25); ``element_stiffness`` is
    :func:`~gfe_opt.elements.beam_stiffness_from_flexibility` (the models) or
    :func:`~gfe_opt.elements.beam_stiffness_from_rigidity` (independent references).
    """
    cracks = model.effects_named("crack")
    EI, L = model.bending_rigidity, model.element_length
    half_depth = model.depth / 2.0

    def rigidity(x):
        q = np.ones_like(x)
        for c in cracks:
            q = q * el.christides_barr_q(x, c.parameters["position"],
                                         c.parameters["depth_ratio"], half_depth)
        return EI * q

    positions = np.array([c.parameters["position"] for c in cracks])
    decay = half_depth / (2.0 * el.SHEN_PIERRE_GAMMA)
    k = np.tile(list(el.euler_bernoulli_stiffness(EI).values()), (model.elements, 1))
    for e in range(model.elements):
        # beyond 18 decay lengths Q differs from 1 by less than 26 e^-36 (~1e-14)
        gap = np.maximum(np.maximum(e * L - positions, positions - (e + 1) * L), 0.0)
        if np.min(gap) < 18 * decay:
            k[e] = element_stiffness(rigidity, e * L, L, positions, decay)
    return {"k_ww": k[:, 0], "k_wt": k[:, 1], "k_tt": k[:, 2]}


def _beam_stiffness_params(model: Model, L: float) -> dict:
    if model.effects_named("crack"):
        out = crack_element_parameters(model, el.beam_stiffness_from_flexibility)
    else:
        out = {k: np.full(model.elements, v)
               for k, v in el.euler_bernoulli_stiffness(model.bending_rigidity).items()}
    shear = model.effects_named("shear")
    if shear:
        g = el.shear_parameter(out["k_ww"] / 12.0, shear[0].parameters["shear_rigidity"], L)
        out = el.timoshenko_correction(out, g)
    return out


def discretise(model: Model) -> Discretisation:
    """Element data of ``model`` including its effects."""
    n, L = model.elements, model.element_length
    nodes = model.nodes
    size = 2 * (2 if model.kind == "beam" else 1)
    extra = np.zeros((n, size, size))
    nodal = []
    mass = _mass_elements(model, L)
    if model.kind == "bar":
        params = {"k": np.full(n, model.axial_rigidity)}
        scale = model.axial_rigidity / (model.mass_per_length * model.length**2)
    else:
        params = _beam_stiffness_params(model, L)
        scale = model.bending_rigidity / (model.mass_per_length * model.length**4)
        t = el.beam_dof_scaling(L)
        tt = t[:, None] * t[None, :]
        for eff in model.effects_named("axial_load"):
            extra = extra + eff.parameters["tension"] * slope_gram(L) * tt
        for eff in model.effects_named("foundation"):
            found = eff.parameters["stiffness"] * L * el.symmetric_beam_mass(
                **el.CONSISTENT_BEAM_MASS)
            extra = extra + found * tt
        for eff in model.effects_named("support_spring"):
            side = eff.parameters["side"]
            ends = {"left": [0], "right": [n], "both": [0, n]}[side]
            nodal += [(2 * node + 1, eff.parameters["stiffness"]) for node in ends]
    for eff in model.effects_named("point_mass"):
        e = min(int(eff.parameters["position"] // L), n - 1)
        xi = eff.parameters["position"] / L - e
        if model.kind == "beam":
            shape = el.hermite(xi) * el.beam_dof_scaling(L)
        else:
            shape = el.linear(xi)
        mass = mass.copy()
        mass[e] += eff.parameters["mass"] * np.outer(shape, shape)
    return Discretisation(kind=model.kind, nodes=nodes, element_length=L,
                          stiffness_params=params, mass=mass, extra_stiffness=extra,
                          nodal_stiffness=tuple(nodal), constrained=constrained_dofs(model),
                          eigenvalue_scale=scale)

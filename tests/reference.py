"""An independent beam for synthetic measurements, written for the tests.

It shares no code with ``gfe_opt``: its own cubic Hermite elements on a fine uniform mesh,
element matrices integrated with Gauss points from arbitrary EI(x) and ρA(x) functions (the
package builds cracks with exact-flexibility elements and uniform sections with closed-form
matrices), point masses and translational springs interpolated with the shape functions
(a body's rotary inertia with their slopes), geometric stiffness for an axial force, a
Winkler foundation, rotational end springs and the four classic supports.  Measurements
come out as plain arrays, with Gaussian noise relative to each mode's largest amplitude
(shapes) and to each frequency.

Also the Timoshenko closed form of a simply supported beam (Blevins; REFERENCES.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

STEEL = {"length": 0.575, "E": 206e9, "rho": 7800.0, "b": 0.009525, "h": 0.03175}


def _hermite(s, h):
    """Cubic Hermite functions and second derivatives on [0, h], physical rotations."""
    n = np.stack([1 - 3 * s**2 + 2 * s**3, h * (s - 2 * s**2 + s**3), 3 * s**2 - 2 * s**3,
                  h * (-(s**2) + s**3)], -1)
    d1 = np.stack([(-6 * s + 6 * s**2) / h, 1 - 4 * s + 3 * s**2, (6 * s - 6 * s**2) / h,
                   -2 * s + 3 * s**2], -1)
    d2 = np.stack([(-6 + 12 * s) / h**2, (-4 + 6 * s) / h, (6 - 12 * s) / h**2,
                   (-2 + 6 * s) / h], -1)
    return n, d1, d2


@dataclass
class ReferenceBeam:
    """A transverse Euler–Bernoulli beam; ``rigidity(x)`` and ``mass(x)`` are multipliers of
    EI and ρA (vectorised callables), everything SI."""

    length: float = STEEL["length"]
    EI: float = STEEL["E"] * STEEL["b"] * STEEL["h"] ** 3 / 12
    rho_a: float = STEEL["rho"] * STEEL["b"] * STEEL["h"]
    supports: tuple = ("pinned", "pinned")
    elements: int = 1200
    gauss: int = 12
    rigidity: object = None
    mass: object = None
    tension: float = 0.0
    foundation: float = 0.0
    point_masses: list = field(default_factory=list)     # (x, kg)
    point_springs: list = field(default_factory=list)    # (x, N/m)
    point_inertias: list = field(default_factory=list)   # (x, kg m²): a body's rotary
    #                                                      inertia, on the slope there
    end_springs: dict = field(default_factory=dict)      # "left"/"right" -> N m/rad
    hinges: list = field(default_factory=list)           # (x, N m/rad): a rotational spring
    #                                                      between the two sides of a node

    def dof_map(self):
        """Element DOFs (n, 4) and the number of DOFs: a hinge gives the element to the
        right of its node (the nearest) its own rotation."""
        n, h = self.elements, self.length / self.elements
        dofs = 2 * np.arange(n)[:, None] + np.arange(4)[None, :]
        size = 2 * (n + 1)
        pairs = []
        for x, k in self.hinges:
            node = int(round(x / h))
            if not 0 < node < n:
                raise ValueError("a hinge must lie inside the beam")
            dofs[node, 1] = size
            pairs.append((2 * node + 1, size, k))
            size += 1
        return dofs, size, pairs

    def _gauss(self):
        n, h = self.elements, self.length / self.elements
        g, w = np.polynomial.legendre.leggauss(self.gauss)
        s = 0.5 * (g + 1.0)
        return n, h, s, 0.5 * w * h, (np.arange(n)[:, None] + s[None, :]) * h

    def matrices(self):
        n, h, s, w, x = self._gauss()
        N, D1, D2 = _hermite(s, h)
        ei = self.EI * (self.rigidity(x) if self.rigidity else np.ones_like(x))
        ra = self.rho_a * (self.mass(x) if self.mass else np.ones_like(x))
        ke = np.einsum("eq,q,qi,qj->eij", ei, w, D2, D2)
        ke += self.tension * np.einsum("q,qi,qj->ij", w, D1, D1)
        ke += self.foundation * np.einsum("q,qi,qj->ij", w, N, N)
        me = np.einsum("eq,q,qi,qj->eij", ra, w, N, N)
        dofs, size, hinges = self.dof_map()
        rows = np.repeat(dofs, 4, axis=1).ravel()
        cols = np.tile(dofs, (1, 4)).ravel()
        K = sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(size, size)).tolil()
        M = sp.coo_matrix((me.ravel(), (rows, cols)), shape=(size, size)).tolil()
        # point masses and springs on w's shape functions, a body's rotary inertia on the
        # slope's (the derivative, index 1 of _hermite)
        for xp, value, target, d in ([(xp, m, M, 0) for xp, m in self.point_masses]
                                     + [(xp, k, K, 0) for xp, k in self.point_springs]
                                     + [(xp, J, M, 1) for xp, J in self.point_inertias]):
            e = min(int(xp / h), n - 1)
            shape = _hermite(np.array(xp / h - e), h)[d]
            idx = dofs[e]
            for a in range(4):
                for b in range(4):
                    target[idx[a], idx[b]] += value * shape[a] * shape[b]
        for side, k in self.end_springs.items():
            dof = 1 if side == "left" else 2 * n + 1
            K[dof, dof] += k
        for a, b, k in hinges:
            K[a, a] += k
            K[b, b] += k
            K[a, b] -= k
            K[b, a] -= k
        fixed = []
        for node, support in ((0, self.supports[0]), (n, self.supports[1])):
            fixed += {"pinned": [2 * node], "clamped": [2 * node, 2 * node + 1],
                      "sliding": [2 * node + 1], "free": []}[support]
        return K.tocsc(), M.tocsc(), np.setdiff1d(np.arange(size), fixed)

    def modes(self, n_modes: int):
        """Frequencies [Hz] and a function giving w at positions for each mode."""
        K, M, free = self.matrices()
        d = sp.diags(1.0 / np.sqrt(M.diagonal()[free]))
        Kf, Mf = (d @ K[free][:, free] @ d).tocsc(), (d @ M[free][:, free] @ d).tocsc()
        v0 = np.ones(Kf.shape[0])
        shift = -self.EI / (self.rho_a * self.length**4)
        lam, vec = spla.eigsh(Kf, k=n_modes, M=Mf, sigma=shift, which="LM", v0=v0)
        order = np.argsort(lam)
        full = np.zeros((K.shape[0], n_modes))
        full[free] = d @ vec[:, order]
        # eigenvalues as Rayleigh quotients with the bending energy from curvatures at the
        # Gauss points (the assembled K loses eps N^4 of relative accuracy, this does not)
        n, h, s, w, x = self._gauss()
        _, _, D2 = _hermite(s, h)
        dofs = self.dof_map()[0]
        curvature = np.einsum("qi,eim->eqm", D2, full[dofs])
        ei = self.EI * (self.rigidity(x) if self.rigidity else np.ones_like(x))
        bending = np.einsum("eq,q,eqm->m", ei, w, curvature**2)
        K_rest, _, _ = ReferenceBeam(**{**self.__dict__, "EI": 0.0}).matrices()
        energy = bending + np.einsum("im,im->m", full, K_rest @ full)
        lam = energy / np.einsum("im,im->m", full, M @ full)
        return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), full

    def measure(self, n_modes: int, sensors, *, shape_noise=0.003, freq_noise=0.0005,
                seed=0):
        """(frequencies [Hz], shapes (n_sensors, n_modes)) at ``sensors`` with noise."""
        freqs, full = self.modes(n_modes)
        h = self.length / self.elements
        sensors = np.asarray(sensors, float)
        e = np.minimum((sensors / h).astype(int), self.elements - 1)
        N = _hermite(sensors / h - e, h)[0]
        dofs = self.dof_map()[0][e]
        shapes = np.einsum("si,sim->sm", N, full[dofs])
        return add_noise(freqs, shapes, shape_noise, freq_noise, seed)


def add_noise(freqs, shapes, shape_noise, freq_noise, seed):
    rng = np.random.default_rng(seed)
    shapes = shapes + shape_noise * np.max(np.abs(shapes), axis=0) * rng.standard_normal(
        shapes.shape)
    freqs = freqs * (1.0 + freq_noise * rng.standard_normal(freqs.size))
    return freqs, shapes


def christides_barr(position, depth_ratio, depth=STEEL["h"], gamma=1.936):
    """EI multiplier of a symmetric crack: Q(x) with d the half-depth (REFERENCES.md)."""
    d = depth / 2.0

    def q(x):
        strength = (1.0 / (1.0 - depth_ratio)) ** 3 - 1.0
        return 1.0 / (1.0 + strength * np.exp(-2.0 * gamma * np.abs(x - position) / d))

    return q


def product(*functions):
    def f(x):
        out = np.ones_like(x)
        for fn in functions:
            out = out * fn(x)
        return out

    return f


def zone(centre, length, ratio):
    """Multiplier ``ratio`` inside [centre - length/2, centre + length/2], 1 outside."""
    def f(x):
        return np.where(np.abs(x - centre) <= length / 2, ratio, 1.0)

    return f


def timoshenko_ss(n_modes, EI, rho_a, rho_i, kga, length):
    """Frequencies [Hz] of a simply supported Timoshenko beam (shear and rotary inertia):
    the lower root of det [[κGA α² − ρA ω², −κGA α], [−κGA α, EI α² + κGA − ρI ω²]] = 0."""
    alpha = np.arange(1, n_modes + 1) * np.pi / length
    a2 = rho_a * rho_i
    a1 = -(rho_a * (EI * alpha**2 + kga) + rho_i * kga * alpha**2)
    a0 = kga * alpha**2 * (EI * alpha**2 + kga) - (kga * alpha) ** 2
    omega2 = 2 * a0 / (-a1 + np.sqrt(a1**2 - 4 * a2 * a0))  # the lower root, no cancellation
    return np.sqrt(omega2) / (2 * np.pi)


def interior(length, count):
    return np.linspace(0.0, length, count + 2)[1:-1]


@dataclass
class ReferenceBar:
    """An axial bar of linear elements with consistent mass on a fine mesh; ``rigidity`` and
    ``mass`` multiply EA and ρA; point masses and axial springs at positions."""

    length: float = 2.0
    EA: float = 70e9 * 1e-4
    rho_a: float = 2700 * 1e-4
    supports: tuple = ("fixed", "free")
    elements: int = 4000
    rigidity: object = None
    mass: object = None
    point_masses: list = field(default_factory=list)
    point_springs: list = field(default_factory=list)

    def measure(self, n_modes, sensors, *, shape_noise=0.003, freq_noise=0.0005, seed=0):
        n, h = self.elements, self.length / self.elements
        g, w = np.polynomial.legendre.leggauss(6)
        s = 0.5 * (g + 1.0)
        w = 0.5 * w * h
        x = (np.arange(n)[:, None] + s[None, :]) * h
        ea = self.EA * (self.rigidity(x) if self.rigidity else np.ones_like(x))
        ra = self.rho_a * (self.mass(x) if self.mass else np.ones_like(x))
        N = np.stack([1 - s, s], -1)
        B = np.array([-1.0, 1.0]) / h
        ke = np.einsum("eq,q,i,j->eij", ea, w, B, B)
        me = np.einsum("eq,q,qi,qj->eij", ra, w, N, N)
        K = np.zeros((n + 1, n + 1))
        M = np.zeros((n + 1, n + 1))
        for a in range(2):
            for b in range(2):
                np.add.at(K, (np.arange(n) + a, np.arange(n) + b), ke[:, a, b])
                np.add.at(M, (np.arange(n) + a, np.arange(n) + b), me[:, a, b])
        for xp, value, target in ([(xp, m, M) for xp, m in self.point_masses]
                                  + [(xp, k, K) for xp, k in self.point_springs]):
            e = min(int(xp / h), n - 1)
            shape = np.array([1 - (xp / h - e), xp / h - e])
            target[e:e + 2, e:e + 2] += value * np.outer(shape, shape)
        fixed = [i for i, sup in ((0, self.supports[0]), (n, self.supports[1]))
                 if sup == "fixed"]
        free = np.setdiff1d(np.arange(n + 1), fixed)
        Kf, Mf = sp.csc_matrix(K[np.ix_(free, free)]), sp.csc_matrix(M[np.ix_(free, free)])
        lam, vec = spla.eigsh(Kf, k=n_modes, M=Mf, sigma=-1.0, which="LM",
                              v0=np.ones(free.size))
        order = np.argsort(lam)
        full = np.zeros((n + 1, n_modes))
        full[free] = vec[:, order]
        shapes = np.stack([np.interp(sensors, np.linspace(0, self.length, n + 1), full[:, j])
                           for j in range(n_modes)], 1)
        freqs = np.sqrt(np.maximum(lam[order], 0.0)) / (2 * np.pi)
        return add_noise(freqs, shapes, shape_noise, freq_noise, seed)


# -------------------------------------------------------------------------------------------
# FRFs of a damped structure (modal superposition of the reference modes)
# -------------------------------------------------------------------------------------------

UFF_FORM_CODES = {"receptance": 8, "mobility": 11, "accelerance": 12}


def synthesise_frfs(natural_hz, shapes, damping, freq, reference, *, form="accelerance",
                    noise=0.0, seed=0):
    """FRFs H_j(f) = Σ_n φ_jn φ_ref,n (iω)^k / (ω_n² − ω² + 2iζ_n ω_n ω) at the points of
    ``shapes`` (n_points, n_modes, mass-normalised or not: the scale is irrelevant here),
    excited or measured at point ``reference``; k = 0, 1, 2 for receptance, mobility,
    accelerance.  Complex Gaussian noise of ``noise`` times each FRF's largest magnitude."""
    w = 2 * np.pi * np.asarray(freq, float)[:, None]
    wn = 2 * np.pi * np.asarray(natural_hz, float)[None, :]
    zeta = np.asarray(damping, float)[None, :]
    power = {"receptance": 0, "mobility": 1, "accelerance": 2}[form]
    modal = (1j * w) ** power / (wn**2 - w**2 + 2j * zeta * wn * w)
    H = np.array([np.sum(shapes[j] * shapes[reference] * modal, axis=1)
                  for j in range(shapes.shape[0])])
    if noise:
        rng = np.random.default_rng(seed)
        scale = noise * np.abs(H).max(axis=1, keepdims=True) / np.sqrt(2)
        H = H + scale * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))
    return H


def write_uff58(path, x, freq, H, reference, *, form="accelerance", roving="hammer"):
    """A universal file: node coordinates (2411) and one dataset 58 per point; with a roving
    hammer the response node is ``reference`` in every FRF, with a roving accelerometer the
    reference (excitation) node is."""
    import pyuff

    n = len(x)
    nodes = np.arange(1, n + 1)
    sets = [pyuff.prepare_2411(node_nums=nodes, def_cs=np.zeros(n, int),
                               disp_cs=np.zeros(n, int), color=np.ones(n, int),
                               x=np.asarray(x, float), y=np.zeros(n), z=np.zeros(n),
                               return_full_dict=True)]
    for j in range(n):
        rsp, ref = (reference + 1, j + 1) if roving == "hammer" else (j + 1, reference + 1)
        sets.append(pyuff.prepare_58(
            func_type=4, rsp_node=rsp, rsp_dir=3, ref_node=ref, ref_dir=3,
            ordinate_spec_data_type=UFF_FORM_CODES[form], abscissa_spec_data_type=18,
            data=np.asarray(H[j], complex), x=np.asarray(freq, float), id1=f"FRF {j + 1}",
            rsp_ent_name="beam", ref_ent_name="beam", abscissa_spacing=1,
            abscissa_min=float(freq[0]), abscissa_inc=float(freq[1] - freq[0]),
            num_pts=len(freq), ver_num=0, load_case_id=0, z_axis_value=0.0,
            orddenom_spec_data_type=13, z_axis_spec_data_type=0))
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")

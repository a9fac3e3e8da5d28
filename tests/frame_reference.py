r"""Exact natural frequencies of plane frames by the dynamic stiffness method (Euler–Bernoulli
members with axial motion; Williams & Wittrick), independent of gfe-opt's elements.

Each member's end forces follow from the exact solution of its equations of motion at
frequency ω: axially u(x) = a cos kx + b sin kx, k = ω √(ρ/E); in bending
w(x) = c₁ cos βx + c₂ sin βx + c₃ cosh βx + c₄ sinh βx, β⁴ = ρAω²/EI.  The end
displacements are B c and the end forces F c (F₁ = EI w‴(0), M₁ = −EI w″(0),
F₂ = −EI w‴(L), M₂ = EI w″(L)), so the member's dynamic stiffness is F B⁻¹; rotated and
assembled as a stiffness matrix, D(ω) is singular at every natural frequency.  A root is
found by bisection of the eigenvalue of D(ω) (in a fixed place of the sorted spectrum) that
crosses zero, in a bracket about an estimate.

A member may carry a constant axial force T (tension > 0; a seventh entry of its tuple):
EI w⁗ − T w″ = ρAω² w, whose solutions are cos βx, sin βx, cosh αx, sinh αx with α², −β²
the roots of EI s² − T s − ρAω² = 0, and whose transverse end forces gain T w′
(F₁ = EI w‴(0) − T w′(0), F₂ = −EI w‴(L) + T w′(L)).  :func:`self_stress` gives the forces
a member's prestrain (a turnbuckle) sets up in a frame, by the exact static stiffness.

A member may lie on a Winkler foundation k_f [N/m²] (an eighth entry; the seventh, its axial
force, then given, 0 for none): EI w⁗ − T w″ + (k_f − ρAω²) w = 0, solved by exp(r x) over
the four (complex) roots r, below the foundation's own frequency √(k_f/ρA) as above it.

A member may be a Timoshenko beam (a ninth entry: its shear rigidity κGA, N; the seventh and
eighth then 0): κGA (w″ − ψ′) + ρAω² w = 0 and EI ψ″ + κGA (w′ − ψ) + ρIω² ψ = 0, ψ the
section's rotation (the joint's θ), with its rotary inertia ρI.  w = e^{rx}, ψ = a e^{rx}
with a = (κGA r² + ρAω²) / (κGA r) and r² the roots of κGA EI s² + ω² (κGA ρI + ρA EI) s
+ ρAω² (ρIω² − κGA) = 0; the end forces F₁ = −κGA (w′ − ψ)(0), M₁ = −EI ψ′(0),
F₂ = κGA (w′ − ψ)(L), M₂ = EI ψ′(L) (Euler–Bernoulli's as κGA → ∞).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

SUPPORTS = {"clamped": (0, 1, 2), "pinned": (0, 1), "roller-x": (1,), "roller-y": (0,)}


def _wavenumbers(E, rho, A, inertia, omega, tension=0.0):
    """(β, α) of a member's transverse motion at ω: w = cos βx, sin βx, cosh αx, sinh αx."""
    EI = E * inertia
    if tension == 0.0:   # β = α = (ρAω²/EI)^¼, in the arithmetic the records were made with
        beta = (rho * A * omega**2 / EI) ** 0.25
        return beta, beta
    root = math.sqrt(tension**2 + 4.0 * EI * rho * A * omega**2)
    return math.sqrt((root - tension) / (2 * EI)), math.sqrt((root + tension) / (2 * EI))


def member_dynamic_stiffness(E, rho, A, inertia, L, omega, tension=0.0,
                             foundation=0.0, shear=None) -> np.ndarray:
    """(6, 6) dynamic stiffness in the member's axes, DOFs u₁, v₁, θ₁, u₂, v₂, θ₂ (with a
    constant axial force ``tension``, N, and a Winkler ``foundation``, N/m²; ``shear``: a
    Timoshenko member's κGA, N)."""
    D = np.zeros((6, 6))
    k = omega * math.sqrt(rho / E)
    if k * L < 1e-8:
        axial = E * A / L * np.array([[1.0, -1.0], [-1.0, 1.0]])
    else:
        axial = E * A * k / math.sin(k * L) * np.array([[math.cos(k * L), -1.0],
                                                         [-1.0, math.cos(k * L)]])
    D[np.ix_([0, 3], [0, 3])] = axial
    EI = E * inertia
    if shear is not None:
        assert tension == 0.0 and foundation == 0.0, "a Timoshenko member: no T, no k_f"
        B, F, _ = _timoshenko(E, rho, A, inertia, omega, shear, L)
        bending = F @ np.linalg.inv(B)
        assert np.max(np.abs(bending.imag)) <= 1e-8 * np.max(np.abs(bending.real))
        D[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = bending.real
        return D
    basis = _transverse(E, rho, A, inertia, omega, tension, foundation)

    def derivs(x):
        """w, w′, w″, w‴ of the four basis functions at x (rows)."""
        return np.array([basis(x, order) for order in range(4)])

    d0, d1 = derivs(0.0), derivs(L)
    B = np.array([d0[0], d0[1], d1[0], d1[1]])
    F = np.array([EI * d0[3] - tension * d0[1], -EI * d0[2],
                  -EI * d1[3] + tension * d1[1], EI * d1[2]])
    bending = F @ np.linalg.inv(B)
    if np.iscomplexobj(bending):   # complex exponentials: a real matrix, to rounding
        assert np.max(np.abs(bending.imag)) <= 1e-8 * np.max(np.abs(bending.real))
        bending = bending.real
    D[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = bending
    return D


def _transverse(E, rho, A, inertia, omega, tension=0.0, foundation=0.0):
    """The four solutions of a member's transverse motion at ω as ``basis(t, order)`` (their
    derivatives of ``order`` at t): cos βt, sin βt, cosh αt, sinh αt (:func:`_basis`); on a
    foundation exp(r t) for the four roots r of EI r⁴ − T r² + k_f − ρAω² = 0 (complex
    where the foundation holds the member above its inertia), distinct but at isolated
    frequencies."""
    if foundation == 0.0:
        beta, alpha = _wavenumbers(E, rho, A, inertia, omega, tension)
        return lambda t, order: _basis(beta, t, order, alpha)
    EI = E * inertia
    disc = np.sqrt(complex(tension**2 - 4.0 * EI * (foundation - rho * A * omega**2)))
    squares = [(tension + disc) / (2 * EI), (tension - disc) / (2 * EI)]
    roots = np.array([sign * np.sqrt(r2) for r2 in squares for sign in (1.0, -1.0)])
    return lambda t, order: roots**order * np.exp(roots * t)


def _timoshenko(E, rho, A, inertia, omega, shear, L):
    """A Timoshenko member at ω: (B, F, w) with B the end values [w(0), ψ(0), w(L), ψ(L)]
    and F the end forces [F₁, M₁, F₂, M₂] of the four solutions e^{rx} (columns), and
    ``w(x)`` their deflections at x."""
    EI, rA, rI = E * inertia, rho * A, rho * inertia
    a2, b2 = shear * EI, omega**2 * (shear * rI + rA * EI)
    c2 = rA * omega**2 * (rI * omega**2 - shear)
    disc = np.sqrt(complex(b2**2 - 4.0 * a2 * c2))
    squares = [(-b2 + disc) / (2 * a2), (-b2 - disc) / (2 * a2)]
    r = np.array([sign * np.sqrt(s2) for s2 in squares for sign in (1.0, -1.0)])
    a = (shear * r**2 + rA * omega**2) / (shear * r)

    def w(x):
        return np.exp(r * x)

    e0, e1 = w(0.0), w(L)
    B = np.array([e0, a * e0, e1, a * e1])
    F = np.array([-shear * (r - a) * e0, -EI * a * r * e0, shear * (r - a) * e1,
                  EI * a * r * e1])
    return B, F, w


class ExactFrame:
    """A frame of uniform members: ``nodes`` {id: (x, y)}, ``members`` [(from, to, E, rho,
    A, I)], ``supports`` {id: type}, ``joint_springs`` [(node, member index, k)],
    ``member_ids`` the members' names (for sensors on them), ``ground_springs`` [(node, DOF
    0/1/2 for u/v/θ, k)]: a support's fixity of that DOF replaced by a spring to ground
    (a direction (cx, cy) for the DOF: a spring to ground along it at a node left free);
    ``masses`` [(node, kg)] or [(node, kg, J)]: a rigid mass at a node (it moves in x and
    y; with J [kg m²], a body that also turns with the joint)."""

    def __init__(self, nodes, members, supports, joint_springs=(), member_ids=None,
                 ground_springs=(), masses=()):
        self.ids = list(nodes)
        self.masses = [(3 * self.ids.index(body[0]) + d, value) for body in masses
                       for d, value in ((0, body[1]), (1, body[1]),
                                        (2, body[2] if len(body) > 2 else 0.0))]
        self.ground = [(3 * self.ids.index(node) + dof, k) for node, dof, k in ground_springs
                       if not isinstance(dof, tuple)]
        # a spring to ground along a direction (cx, cy) at a node no support holds there
        self.leaning = [(3 * self.ids.index(node), np.array(dof, dtype=float), k)
                        for node, dof, k in ground_springs if isinstance(dof, tuple)]
        self.member_ids = list(member_ids or range(len(members)))
        self.nodes = nodes
        self.members = members
        n = 3 * len(self.ids)
        self.end_theta = {}
        self.springs = []
        for node, m, k in joint_springs:
            self.end_theta[(m, node)] = n
            self.springs.append((3 * self.ids.index(node) + 2, n, k))
            n += 1
        self.n = n
        fixed = {3 * self.ids.index(i) + d for i, t in supports.items() for d in SUPPORTS[t]}
        fixed -= {dof for dof, _ in self.ground}
        self.free = np.array([d for d in range(n) if d not in fixed])
        E, _, _, inertia = members[0][2:6]
        L = max(self._length(m) for m in members)
        self.scale = E * inertia / L**3

    def _length(self, m):
        (x0, y0), (x1, y1) = self.nodes[m[0]], self.nodes[m[1]]
        return math.hypot(x1 - x0, y1 - y0)

    def matrix(self, omega) -> np.ndarray:
        D = np.zeros((self.n, self.n))
        for k, m in enumerate(self.members):
            a, b, E, rho, A, inertia = m[:6]
            (x0, y0), (x1, y1) = self.nodes[a], self.nodes[b]
            L = math.hypot(x1 - x0, y1 - y0)
            c, s = (x1 - x0) / L, (y1 - y0) / L
            R = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
            T = np.zeros((6, 6))
            T[:3, :3], T[3:, 3:] = R, R
            dofs = self._member_dofs(k)
            Dm = member_dynamic_stiffness(E, rho, A, inertia, L, omega, _tension(m),
                                          _foundation(m), _shear(m))
            D[np.ix_(dofs, dofs)] += T.T @ Dm @ T
        for i, j, k in self.springs:
            D[np.ix_([i, j], [i, j])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
        for i, k in self.ground:
            D[i, i] += k
        for i, d, k in self.leaning:
            D[i:i + 2, i:i + 2] += k * np.outer(d, d)
        for i, m in self.masses:
            D[i, i] -= omega**2 * m
        return D[np.ix_(self.free, self.free)] / self.scale

    def frequency_near(self, estimate_hz, width=1e-3) -> float:
        """The natural frequency [Hz] within ``width`` (relative) of ``estimate_hz``."""
        w0 = 2 * math.pi * estimate_hz
        lam = np.linalg.eigvalsh(self.matrix(w0))
        j = int(np.argmin(np.abs(lam)))

        def g(w):
            return np.linalg.eigvalsh(self.matrix(w))[j]

        lo, hi = w0 * (1 - width), w0 * (1 + width)
        if g(lo) * g(hi) > 0:
            raise ValueError(f"no root within {width:g} of {estimate_hz:g} Hz")
        return brentq(g, lo, hi, xtol=1e-14 * w0, rtol=1e-15) / (2 * math.pi)

    def _member_dofs(self, k) -> list[int]:
        """u, v, θ at the member's start, then at its end (a joint spring's own θ)."""
        a, b = self.members[k][:2]
        dofs = [3 * self.ids.index(a) + i for i in range(3)] + \
               [3 * self.ids.index(b) + i for i in range(3)]
        if (k, a) in self.end_theta:
            dofs[2] = self.end_theta[(k, a)]
        if (k, b) in self.end_theta:
            dofs[5] = self.end_theta[(k, b)]
        return dofs

    def _member_axes(self, k):
        a, b = self.members[k][:2]
        (x0, y0), (x1, y1) = self.nodes[a], self.nodes[b]
        L = math.hypot(x1 - x0, y1 - y0)
        return L, (x1 - x0) / L, (y1 - y0) / L

    def mode_shape(self, frequency_hz, sensors) -> np.ndarray:
        """The exact mode at a natural frequency, read by ``sensors`` (the frame measured-data
        contract: a node, or a member and position; direction "x", "y" or degrees): the
        joint displacements from the null vector of D(ω), each member's interior from its
        own exact solution between them."""
        w = 2 * math.pi * frequency_hz
        _, _, vt = np.linalg.svd(self.matrix(w))
        full = np.zeros(self.n)
        full[self.free] = vt[-1]
        # the null vector's sign: its first entry within 1e-6 of the largest magnitude
        # positive (a symmetric frame's modes have equal peaks; rounding picks between them)
        peak = np.flatnonzero(np.abs(full) >= (1 - 1e-6) * np.max(np.abs(full)))[0]
        full *= np.sign(full[peak])
        out = []
        for s in sensors:
            d = s["direction"]
            angle = math.radians({"x": 0.0, "y": 90.0}.get(d, d) if isinstance(d, str) else d)
            direction = np.array([math.cos(angle), math.sin(angle)])
            if "node" in s:
                i = 3 * self.ids.index(s["node"])
                out.append(direction @ full[i:i + 2])
                continue
            k = self.member_ids.index(s["member"])
            a, b, E, rho, A, inertia = self.members[k][:6]
            L, c, sn = self._member_axes(k)
            R = np.array([[c, sn], [-sn, c]])
            dofs = self._member_dofs(k)
            g = full[dofs]
            u1, v1 = R @ g[0:2]
            u2, v2 = R @ g[3:5]
            x = s["position"]
            ka = w * math.sqrt(rho / E)
            axial = (u1 * math.sin(ka * (L - x)) + u2 * math.sin(ka * x)) / math.sin(ka * L)
            if _shear(self.members[k]) is not None:
                B, _, deflection = _timoshenko(E, rho, A, inertia, w, _shear(self.members[k]),
                                               L)
                coef = np.linalg.solve(B, np.array([v1, g[2], v2, g[5]], dtype=complex))
                transverse = float(np.real(deflection(x) @ coef))
            else:
                basis = _transverse(E, rho, A, inertia, w, _tension(self.members[k]),
                                    _foundation(self.members[k]))
                B = np.array([basis(0, 0), basis(0, 1), basis(L, 0), basis(L, 1)])
                coef = np.linalg.solve(B, [v1, g[2], v2, g[5]])
                transverse = float(np.real(basis(x, 0) @ coef))
            out.append(direction @ (R.T @ np.array([axial, transverse])))
        return np.array(out)


def _basis(beta, t, order, alpha=None):
    """cos βt, sin βt, cosh αt, sinh αt (α = β without an axial force) or their derivative
    of ``order`` (0 to 3)."""
    a = beta if alpha is None else alpha
    c, s, ch, sh = math.cos(beta * t), math.sin(beta * t), math.cosh(a * t), math.sinh(a * t)
    b = beta
    return np.array([[c, s, ch, sh],
                     [-b * s, b * c, a * sh, a * ch],
                     [-b * b * c, -b * b * s, a * a * ch, a * a * sh],
                     [b**3 * s, -b**3 * c, a**3 * sh, a**3 * ch]][order])


def _tension(member) -> float:
    """A member tuple's axial force (its seventh entry; 0 without one)."""
    return float(member[6]) if len(member) > 6 else 0.0


def _foundation(member) -> float:
    """A member tuple's foundation modulus k_f (its eighth entry; 0 without one)."""
    return float(member[7]) if len(member) > 7 else 0.0


def _shear(member):
    """A member tuple's shear rigidity κGA (its ninth entry; None: Euler–Bernoulli)."""
    return float(member[8]) if len(member) > 8 and member[8] is not None else None


def member_static_stiffness(E, A, inertia, L) -> np.ndarray:
    """(6, 6) exact static stiffness of a uniform Euler–Bernoulli member in its axes."""
    EA, EI = E * A, E * inertia
    K = np.zeros((6, 6))
    K[np.ix_([0, 3], [0, 3])] = EA / L * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = EI / L**3 * np.array(
        [[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
         [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    return K


def self_stress(nodes, members, supports, shortened, strain) -> list[float]:
    """The axial force [N] (tension > 0) of every member of a frame (``nodes``, ``members``,
    ``supports`` as :class:`ExactFrame` takes them; rigid joints) when member ``shortened``
    (its index) is made shorter by ``strain`` × its length before it is fitted in, as a
    turnbuckle does: the linear static solution by the exact member stiffness."""
    ids = list(nodes)
    n = 3 * len(ids)
    K, f = np.zeros((n, n)), np.zeros(n)
    axes = []
    for k, (a, b, E, _, A, inertia) in enumerate(m[:6] for m in members):
        (x0, y0), (x1, y1) = nodes[a], nodes[b]
        L = math.hypot(x1 - x0, y1 - y0)
        c, s = (x1 - x0) / L, (y1 - y0) / L
        R = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        T = np.zeros((6, 6))
        T[:3, :3], T[3:, 3:] = R, R
        dofs = [3 * ids.index(a) + i for i in range(3)] + [3 * ids.index(b) + i for i in range(3)]
        K[np.ix_(dofs, dofs)] += T.T @ member_static_stiffness(E, A, inertia, L) @ T
        locked = E * A * strain if k == shortened else 0.0   # its pull on its end nodes
        f[dofs] += locked * np.array([c, s, 0.0, -c, -s, 0.0])
        axes.append((dofs, c, s, E * A / L, locked))
    fixed = {3 * ids.index(i) + d for i, t in supports.items() for d in SUPPORTS[t]}
    free = np.array([d for d in range(n) if d not in fixed])
    u = np.zeros(n)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
    return [float(stiffness * (c * (u[dofs[3]] - u[dofs[0]]) + s * (u[dofs[4]] - u[dofs[1]]))
                  + locked) for dofs, c, s, stiffness, locked in axes]


def zone_frame(model, member_id, a, b, stiffness_ratio, area_ratio, ground_springs=()):
    """The exact frame of ``model`` (a :class:`~gfe_opt.frame.FrameModel`, read for its
    geometry and sections only) with member ``member_id`` split at a and b (m from its start;
    either may be an end; b = a: one cut) and the part between them of I ×
    ``stiffness_ratio`` and A × ``area_ratio`` (EA and ρA with it), and ``where``, which maps
    a sensor of the model to the split frame's (its parts are named ``<member>-0``, ``-1``
    ...).  ``ground_springs`` as :class:`ExactFrame`'s (the cut at a is node ``Z1``)."""
    member = next(m for m in model.members if m.id == member_id)
    (x0, y0), (x1, y1) = model.nodes[member.start], model.nodes[member.end]
    L = math.hypot(x1 - x0, y1 - y0)
    nodes, members, names = dict(model.nodes), [], []
    cuts = [(0.0, member.start)]
    for t, name in ((a, "Z1"), (b, "Z2"))[:1 if b == a else 2]:
        # a part shorter than 1e-3 of the member is its end (the exact member's end
        # conditions lose rank as its length goes to 0: a draw 1e-6 from an end failed)
        if 1e-3 * L < t < (1 - 1e-3) * L:
            nodes[name] = (x0 + t / L * (x1 - x0), y0 + t / L * (y1 - y0))
            cuts.append((t, name))
    cuts.append((L, member.end))
    for m in model.members:
        if m.id != member_id:
            members.append((m.start, m.end, m.E, m.rho, m.area, m.inertia))
            names.append(m.id)
            continue
        for i, ((t0, n0), (t1, n1)) in enumerate(zip(cuts[:-1], cuts[1:])):
            inside = a - 1e-3 * L <= t0 and t1 <= b + 1e-3 * L
            members.append((n0, n1, m.E, m.rho, m.area * (area_ratio if inside else 1.0),
                            m.inertia * (stiffness_ratio if inside else 1.0)))
            names.append(f"{m.id}-{i}")
    starts = [t for t, _ in cuts[:-1]]

    def where(sensor):
        if sensor.get("member") != member_id:
            return sensor
        i = max(k for k, t in enumerate(starts) if t <= sensor["position"])
        return {**sensor, "member": f"{member_id}-{i}",
                "position": sensor["position"] - starts[i]}

    return ExactFrame(nodes, members, dict(model.supports), (), names, ground_springs), where


def taper_frame(model, member_id, end_ratio, segments=60, quantity="EI"):
    """The exact frame of ``model`` (geometry and sections) with member ``member_id``'s EI
    varying linearly from its own at the member's start to ``end_ratio`` times that at its
    end (ρA and EA as modelled: a web or flange tapered in depth, its mass kept), built as
    ``segments`` uniform exact members of the EI at their midpoints (a stepped taper, whose
    frequencies converge to the smooth one's as segments⁻²), and ``where``, which maps a
    sensor of the model to the stepped frame's (parts ``<member>-0``, ``-1`` ...).  With
    ``quantity="rhoA"`` its density varies so instead (ρA(x): a non-structural mass laid
    along it unevenly), EI and EA as modelled."""
    member = next(m for m in model.members if m.id == member_id)
    (x0, y0), (x1, y1) = model.nodes[member.start], model.nodes[member.end]
    L = math.hypot(x1 - x0, y1 - y0)
    nodes, members, names = dict(model.nodes), [], []
    ends = [member.start, *(f"T{i}" for i in range(1, segments)), member.end]
    for i in range(1, segments):
        nodes[f"T{i}"] = (x0 + i / segments * (x1 - x0), y0 + i / segments * (y1 - y0))
    for m in model.members:
        if m.id != member_id:
            members.append((m.start, m.end, m.E, m.rho, m.area, m.inertia))
            names.append(m.id)
            continue
        for i in range(segments):
            ratio = 1.0 + (end_ratio - 1.0) * (i + 0.5) / segments
            if quantity == "rhoA":
                members.append((ends[i], ends[i + 1], m.E, m.rho * ratio, m.area, m.inertia))
            else:
                members.append((ends[i], ends[i + 1], m.E, m.rho, m.area, m.inertia * ratio))
            names.append(f"{m.id}-{i}")
    step = L / segments

    def where(sensor):
        if sensor.get("member") != member_id:
            return sensor
        i = min(int(sensor["position"] / step), segments - 1)
        return {**sensor, "member": f"{member_id}-{i}",
                "position": sensor["position"] - i * step}

    return ExactFrame(nodes, members, dict(model.supports), (), names), where

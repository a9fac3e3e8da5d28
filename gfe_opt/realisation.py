r"""Physical realisation (paper section 3): discrete equations turned into continuous ones.

A row of :math:`K u + M \ddot u = 0` at node i couples the DOFs of the neighbouring nodes.
Expanding every neighbour's displacement about node i,
:math:`u_{i+s} = \sum_n (sL)^n/n!\; u_i^{(n)}` (a rotation DOF is the slope, so it expands
:math:`u'`), turns the row into a series of differential operators sorted by powers of the
element length L.  Comparing the series with known governing equations tells what physics the
updated matrices hold.

* :func:`taylor_expand_row` — symbolic (sympy), any stencil of bar or beam DOFs;
* :func:`bar_row` / :func:`beam_row` — the paper's rows (eqs. 3, 5; eq. 12 with eq. 13);
* :func:`nodal_equations` — numeric: at every node of a model, the coefficients of
  w, w', w'', w''', w'''' (stiffness side) and ẅ, ẅ'' (mass side) per unit length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import elements as el
from .assembly import Discretisation

#: the symbolic rows (:mod:`gfe_opt.symbolic_rows`), loaded with sympy only when asked for
_SYMBOLIC = ("x", "L", "u", "k", "m", "t", "shift", "taylor_expand_row", "bar_row", "beam_row")


def __getattr__(name):
    """``gfe_opt.realisation.bar_row`` and the other symbolic names, from
    :mod:`gfe_opt.symbolic_rows` (PEP 562: sympy loads on the first such use)."""
    if name in _SYMBOLIC:
        from . import symbolic_rows

        return getattr(symbolic_rows, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# -------------------------------------------------------------------------------------------
# Numeric realisation of a discretised model
# -------------------------------------------------------------------------------------------

STIFFNESS_TERMS = ("w", "w'", "w''", "w'''", "w''''")
MASS_TERMS = ("ẅ", "ẅ'", "ẅ''")


@dataclass(frozen=True)
class NodalEquation:
    """Continuous equation represented by node i's translational row, per unit length:
    sum_n stiffness[n] w^(n) + sum_n mass[n] w_tt^(n) = 0."""

    x: float
    stiffness: np.ndarray  # coefficients of w, w', w'', w''', w'''' per unit length
    mass: np.ndarray       # coefficients of ẅ, ẅ', ẅ''


@dataclass(frozen=True)
class Realisation:
    """What node i's updated equation says next to the initial model's, in physical terms:
    (k(x) w'')'' - T w'' + k_f w + m ẅ = 0, with k'' taken from neighbouring nodes."""

    x: float
    k_ratio: float       # k / k0, from the coefficient of the fourth derivative
    tension: float       # T [N] in -T w'' beyond what (k w'')'' explains
    foundation: float    # k_f [N/m^2], coefficient of w beyond the initial model's
    mass_ratio: float    # m / m0, from the coefficient of the acceleration

    def describe(self) -> str:
        """The local reading; uniform terms (tension, foundation) are read along the whole
        beam by :func:`summarise`, since one node's w'' and w terms also carry k''."""
        text = (f"near x = {self.x:.3f} m: (k(x) w'')'' + m ẅ = 0 with k = {self.k_ratio:.2f} "
                "of the model's")
        if abs(self.mass_ratio - 1) > 1e-3:
            text += f", m = {self.mass_ratio:.2f} m0"
        return text


def realise(disc: Discretisation, initial: Discretisation, significance: float = 1e-3
            ) -> list[Realisation]:
    """Compare the nodal equations of an updated (or fitted) model with the initial model's.

    Terms below ``significance`` of their natural scale (k0 (π/ℓ)², k0 (π/ℓ)⁴ with ℓ the
    length of the structure) are reported as zero.
    """
    return _compare_rows(nodal_equations(disc), nodal_equations(initial),
                         disc.nodes[-1] - disc.nodes[0], significance)


def _compare_rows(new, old, length: float, significance: float) -> list[Realisation]:
    """:func:`realise`'s reading of rows ``new`` against ``old`` along a length."""
    x = np.array([e.x for e in new])
    c4 = np.array([e.stiffness[4] for e in new])
    c4_old = np.array([e.stiffness[4] for e in old])
    k0 = float(np.mean(c4_old))
    if len(x) >= 2:
        kpp = np.gradient(np.gradient(c4, x), x) - np.gradient(np.gradient(c4_old, x), x)
    else:   # one interior node (a frame member of two elements): no k'' to read
        kpp = np.zeros(len(x))
    out = []
    for i, (a, b) in enumerate(zip(new, old)):
        tension = -((a.stiffness[2] - b.stiffness[2]) - kpp[i])
        foundation = a.stiffness[0] - b.stiffness[0]
        if abs(tension) < significance * k0 * (np.pi / length) ** 2:
            tension = 0.0
        if abs(foundation) < significance * k0 * (np.pi / length) ** 4:
            foundation = 0.0
        # node by node against the initial model: a crack it already holds is no change
        out.append(Realisation(float(a.x), float(a.stiffness[4] / b.stiffness[4]),
                               float(tension), float(foundation),
                               float(a.mass[0] / b.mass[0])))
    return out


def _series(entries, L: float):
    """One row's Taylor coefficients per unit length from its entries ``(K value, M value,
    h, d)``: the column's node lies h from the row's, d = 0 a displacement DOF (expands
    w^(n) h^n/n!), d = 1 a rotation (the slope: w^(n+1) h^n/n!)."""
    stiff = np.zeros(5)
    mass = np.zeros(3)
    for kv, mv, h, d in entries:
        for n in range(5):
            p = n - d
            if p >= 0:
                stiff[n] += kv * h**p / math.factorial(p)
        for n in range(3):
            p = n - d
            if p >= 0:
                mass[n] += mv * h**p / math.factorial(p)
    return stiff / L, mass / L


def nodal_equations(disc: Discretisation, K=None, M=None) -> list[NodalEquation]:
    """Numeric Taylor expansion of every interior node's translational row (beam) or row
    (bar) of the assembled K and M; coefficients per unit length (divided by the element
    length, as the row integrates over two half elements)."""
    if K is None or M is None:
        K, M = disc.global_matrices()
    nodes = disc.nodes
    per = disc.dofs_per_node
    # every interior node's entries read at once (one by one, the sparse lookups were a
    # third of a 2 000-element realisation's time): row per·i, columns per·j + d for
    # j = i − 1, i, i + 1 and each DOF d of a node
    interior = np.arange(1, len(nodes) - 1)
    near = interior[:, None] + np.array([-1, 0, 1])[None, :]
    cols = (per * near[:, :, None] + np.arange(per)[None, None, :]).reshape(len(interior), -1)
    rows = np.repeat(per * interior, cols.shape[1])
    Kv, Mv = (np.asarray(A.tocsr()[rows, cols.ravel()]).reshape(cols.shape) for A in (K, M))
    out = []
    for k, i in enumerate(interior):
        entries = [(Kv[k, per * a + d], Mv[k, per * a + d], nodes[j] - nodes[i], d)
                   for a, j in enumerate((i - 1, i, i + 1)) for d in range(per)]
        out.append(NodalEquation(float(nodes[i]), *_series(entries, disc.element_length)))
    return out


@dataclass(frozen=True)
class MemberRealisation:
    """What a frame member's interior nodes say in the member's own axes: its transverse
    rows read as a beam's (:class:`Realisation`, x from its start node) and its axial rows'
    EA / EA0 (the coefficient of u'': -EA for a bar, eq. 8)."""

    member: str
    start: str
    length: float
    rows: tuple
    axial_ratio: np.ndarray
    bending_rigidity: float   # the model's EI of the member

    @property
    def euler_load(self) -> float:
        """π² EI / ℓ²: the scale an axial force must reach to matter in its bending."""
        return float(np.pi**2 * self.bending_rigidity / self.length**2)


def member_equations(disc, K=None, M=None) -> dict:
    """Each frame member's interior nodes Taylor-expanded in the member's axes (the frame's
    K and M rotated to its transverse and axial directions, its own end rotations where a
    joint spring frees them): {member: (transverse NodalEquation list, each axial row's
    coefficient of u'' per unit length)}.  ``disc`` is a frame discretisation or its
    generic form (``mesh``, ``model``, :meth:`global_matrices`)."""
    if K is None or M is None:
        K, M = disc.global_matrices()
    K, M = K.tocsr(), M.tocsr()
    mesh = disc.mesh
    out = {}
    for k, member in enumerate(disc.model.members):
        els = np.flatnonzero(mesh.element_member == k)
        c, s = mesh.cosines[els[0]]
        L = float(mesh.element_length[els[0]])
        rows, axial = [], []
        for p in range(1, len(els)):
            left, right = mesh.element_dofs[els[p - 1]], mesh.element_dofs[els[p]]
            nodes = (left[:3], left[3:], right[3:])
            here = nodes[1]
            across = {w: -s * W[here[0]].toarray()[0] + c * W[here[1]].toarray()[0]
                      for w, W in (("K", K), ("M", M))}
            along = c * K[here[0]].toarray()[0] + s * K[here[1]].toarray()[0]
            entries = []
            u2 = 0.0
            for j, dofs in zip((-1, 0, 1), nodes):
                h = j * L
                entries.append((-s * across["K"][dofs[0]] + c * across["K"][dofs[1]],
                                -s * across["M"][dofs[0]] + c * across["M"][dofs[1]], h, 0))
                entries.append((across["K"][dofs[2]], across["M"][dofs[2]], h, 1))
                u2 += (c * along[dofs[0]] + s * along[dofs[1]]) * h**2 / 2.0
            rows.append(NodalEquation(p * L, *_series(entries, L)))
            axial.append(u2 / L)
        out[member.id] = (rows, np.array(axial))
    return out


def realise_members(disc, initial, significance: float = 1e-3) -> list[MemberRealisation]:
    """:func:`realise` on a frame, member by member in each member's axes (its length the
    scale of the terms' significance)."""
    new, old = member_equations(disc), member_equations(initial)
    model = initial.model
    out = []
    for member in disc.model.members:
        (rows, u2), (rows0, u20) = new[member.id], old[member.id]
        length = disc.model.member_length(member)
        read = _compare_rows(rows, rows0, length, significance) if rows else []
        out.append(MemberRealisation(member.id, member.start, length, tuple(read), u2 / u20,
                                     model.stiffness_factor * member.E * member.inertia))
    return out


def summarise(realisations: list[Realisation]) -> list[str]:
    """The physics the nodal equations point to, in words (uniform terms by their median,
    local ones by their extreme node)."""
    k = np.array([r.k_ratio for r in realisations])
    m = np.array([r.mass_ratio for r in realisations])
    tension = uniform_term([r.tension for r in realisations])
    foundation = uniform_term([r.foundation for r in realisations])
    lines = []
    if abs(np.median(k) - 1) > 5e-3:
        lines.append(f"uniform bending stiffness {np.median(k):.3f} k0 (a material change)")
    i = int(np.argmin(k))
    if k[i] < 0.95 * np.median(k):
        lines.append(f"local stiffness loss: {realisations[i].describe()}")
    if tension:
        lines.append(f"a -T w'' term along the beam with T = {tension:.4g} N (axial load)")
    if foundation:
        lines.append(f"a k_f w term along the beam with k_f = {foundation:.4g} N/m² "
                     "(elastic foundation)")
    j = int(np.argmax(m))
    if m[j] > 1.05:
        lines.append(f"local mass {m[j]:.2f} m0 near x = {realisations[j].x:.3f} m "
                     "(attached mass)")
    return lines


def uniform_term(values) -> float:
    """The median of a term that is present along the whole beam with one sign and a small
    spread (80 % of the nodes, interquartile range below half the median), else 0."""
    v = np.asarray(values, float)
    if v.size == 0:   # no interior node (a frame member of one element)
        return 0.0
    med = float(np.median(v))
    if med == 0.0 or np.mean(np.sign(v) == np.sign(med)) < 0.8:
        return 0.0
    q1, q3 = np.percentile(v, [25, 75])
    return med if (q3 - q1) < 0.5 * abs(med) else 0.0


# -------------------------------------------------------------------------------------------
# The generic update of noisy data: its profile, its noise band and what it shows
# -------------------------------------------------------------------------------------------

#: re-solves of the generic update with fresh noise for the band
BAND_SAMPLES = 6
#: a feature of the profile is significant beyond this many standard deviations
FEATURE_SIGMAS = 3.0
#: ... and, for a local one, this relative change (the update's own systematic scatter)
FEATURE_CHANGE = 0.05
#: a nodal stiffness ratio at or below this is the update collapsing, not a reading
COLLAPSED = 0.05


@dataclass(frozen=True)
class Feature:
    """Something the generic profile shows: ``kind`` is ``"uniform"``, ``"taper"``,
    ``"loss"`` or ``"rise"``; ``x`` where (m; the extreme node of a local feature),
    ``x_from``/``x_to`` its extent, ``value`` the ratio k/k_model there (for a taper: at
    the right end, with ``start`` at the left) and ``sigma`` its standard deviation."""

    kind: str
    x: float
    x_from: float
    x_to: float
    value: float
    sigma: float
    start: float = 1.0
    significance: float = 0.0   # in standard deviations (what orders features)

    def describe(self, ends=("the left end", "the right end"), quantity="EI",
                 level: float = 1.0) -> str:
        """In words; ``ends`` name where x starts and ends (a frame member's nodes),
        ``quantity`` what was read: ``"EI"`` (bending) or ``"EA"`` (a member's axial);
        ``level`` the profile's level a local feature stands out from (a frame member's,
        when it is not the model's)."""
        axial = quantity == "EA"
        if self.kind == "uniform":
            why = "a looser or thinner member" if axial else "a material change"
            return (f"a uniform change of {quantity}: {self.value:.3f} ± {self.sigma:.3f} of "
                    f"the model's ({why})")
        if self.kind == "taper":
            return (f"{quantity} tapers from {self.start:.3f} of the model's at {ends[0]} to "
                    f"{self.value:.3f} at {ends[1]} (± {self.sigma:.3f}): a taper")
        word = ("axial stiffness " if axial else "stiffness ") + (
            "loss" if self.kind == "loss" else "rise")
        # an axial reading is of elements, at their middles (:func:`_line_reading`)
        extent = (("at one element" if axial else "at one node") if self.x_from == self.x_to
                  else f"{self.x_from:.3f} to {self.x_to:.3f} m")
        if self.value <= COLLAPSED:
            return (f"the update collapses near x = {self.x:.3f} m ({extent}): k = "
                    f"{self.value:.2f} of the model's, no physical reading (the nodal family "
                    "cannot fit the data there)")
        if level != 1.0:   # against the member's own level, said as such
            return (f"a local {word} near x = {self.x:.3f} m ({extent}): k = "
                    f"{self.value * level:.2f} of the model's, {self.value:.2f} ± "
                    f"{self.sigma:.2g} of the member's level there ({level:.2f} of the "
                    "model's)")
        return (f"a local {word} near x = {self.x:.3f} m ({extent}): "
                f"k = {self.value:.2f} ± {self.sigma:.2g} of the model's")

    def brief(self, quantity="EI") -> str:
        """In a few words, its value as the figure labels it (a further feature:
        :func:`describe_profile`)."""
        if self.kind == "taper":
            return f"a taper of {quantity} ({self.start:.2f} to {self.value:.2f})"
        if self.kind == "uniform":
            return f"{quantity} uniformly {self.value:.3f}"
        if self.value <= COLLAPSED:
            return f"a collapse at x = {self.x:.3f} m"
        what = ("an axial " if quantity == "EA" else "a ") + self.kind
        return f"{what} at x = {self.x:.3f} m ({self.value:.2f})"


@dataclass(frozen=True)
class ProfileBand:
    """Nodal k_i / k_i0 of the generic update against its null profile, its standard
    deviation under the null, the trend and the features beyond :data:`FEATURE_SIGMAS`;
    ``explained`` is the same reading of a fitted model's own modes (None until
    :func:`explain` sets it) and ``unexplained`` the features of data over explained."""

    x: np.ndarray
    ratio: np.ndarray
    sigma: np.ndarray
    trend: np.ndarray
    features: tuple
    null: np.ndarray
    explained: np.ndarray | None = None
    unexplained: tuple = ()
    #: what was read: "EI" (a beam's bending, at its nodes) or "EA" (a bar's axial, at its
    #: elements' middles)
    quantity: str = "EI"
    #: the features beyond the band less significant than the three of ``features``: said
    #: and drawn (the figure shows every node beyond the band; the words named only the
    #: three), not weighed by the diagnosis, which reads ``features``
    further: tuple = ()


def _generic_ratio_of(disc, data, noise):
    from .updating import update_generic

    try:
        if disc.kind == "frame":
            from .frame_generic import member_ratios, update_frame_generic

            result = update_frame_generic(disc.model, data, noise=max(noise.shape, 1e-3))
            return (np.concatenate([r for axial in (False, True)
                                    for _, r in member_ratios(result, axial).values()])
                    if result.ok else None)
        result = update_generic(disc, data, noise=max(noise.shape, 1e-3))
    except (ValueError, np.linalg.LinAlgError):
        return None
    return _line_reading(disc, result)[1] if result.ok else None


def _line_reading(disc, result):
    """(x, k / k0, quantity) of a beam's or bar's generic update: a beam's nodal k_i at its
    nodes ("EI"); a bar's element EA, as its parameterisation makes them of its nodal
    values (eq. 7), at the elements' middles ("EA").  A bar is read at its elements: its
    nodal values have a null space, the vector alternating +a, −a from node to node, which
    changes no element, and the regularisation alone holds it.  It did not hold it on a
    fixed-free bar (the free end's nodes, which the data leave open, pulled it out): nodes
    read 1.09 and 0.92 of the model's in turn along the whole bar of the model's own
    modes, where its elements read within 0.9 % of 1 over its first three quarters (the
    free end's, which the data leave open, falls to 0.57; the ``bar-*`` rows of
    ``scripts/study_discrepancy.py``; a frame's members are read so, axially, already)."""
    n = disc.n_elements
    x = np.asarray(disc.nodes, dtype=float)
    q, q0 = result.q[:n + 1], result.q0[:n + 1]
    if disc.kind == "bar":
        A = result.parameterisation.matrix
        return 0.5 * (x[1:] + x[:-1]), (A @ q) / (A @ q0), "EA"
    return x, q / q0, "EI"


def _profile_size(disc) -> int:
    """How many nodal values the generic update's profile has: the beam's nodes, or every
    member's own nodes on a frame (a joint once per member)."""
    if disc.kind == "frame":   # bending at the nodes, then axial at the elements
        return sum(2 * m.elements + 1 for m in disc.model.members)
    return disc.n_elements + (disc.kind != "bar")   # a bar at its elements


def vibrating_modes(disc: Discretisation, n_modes: int):
    """The lowest ``n_modes`` modes of ``disc`` after its rigid-body modes (a free or
    pinned-free model has them; a test never measures them)."""
    from .modal import Modes, discretisation_modes, rigid_body_count

    rigid = rigid_body_count(disc)
    modes = discretisation_modes(disc, n_modes + rigid)
    return Modes(frequencies_hz=modes.frequencies_hz[rigid:rigid + n_modes],
                 shapes=modes.shapes[:, rigid:rigid + n_modes])


def own_modes(disc: Discretisation, measured):
    """The vibrating modes of ``disc`` at the measured sensors, noise-free, as measured data
    (as many as were measured; a 0 Hz "measured" mode would be refused as bad input)."""
    from .measured import observation

    modes = vibrating_modes(disc, measured.n_modes)
    C = observation(disc, measured)
    return _as_measured(measured, modes.frequencies_hz, C @ modes.shapes)


def _as_measured(like, frequencies_hz, shapes):
    """Measured modes at the sensors of ``like`` (a beam's test or a frame's)."""
    if hasattr(like, "sensors"):   # a frame's: the same sensors, these modes
        from dataclasses import replace

        return replace(like, frequencies_hz=np.asarray(frequencies_hz, float),
                       shapes=np.asarray(shapes, float))
    from .measured import make_measured

    return make_measured(like.x, like.dof, frequencies_hz, shapes, like.source)


def profile_band(disc: Discretisation, measured, result, noise, samples: int = BAND_SAMPLES,
                 seed: int = 0, draws=None) -> ProfileBand:
    """The generic update's nodal k_i / k_i0 read against two references:

    * its **null profile**, the mean of the same update on ``samples`` copies of the model's
      own modes at the same sensors with noise of the stated level: where the model holds
      something the nodal family cannot (the exact elements of a crack), the update moves
      even on data the model fits, and that is not a finding;
    * its **noise band**, the spread of those copies (fixed seed: reproducible): what the
      update shows when the model is right.  (Adding noise to the measured data instead
      doubles the noise, and the expansion, tuned to the stated level, swings by tens of %.)

    ``draws``: the updates (:func:`generic_ratio`) of :func:`noisy_copies` ``(disc,
    measured, noise, samples, seed)`` already run (in parallel, by the diagnosis); None
    runs them here."""
    own = own_modes(disc, measured)
    if draws is None:
        draws = [generic_ratio(disc, c, noise) for c in _copies(own, noise, samples, seed)]
    null, sigma = draws_summary(draws, _profile_size(disc))
    if disc.kind == "frame":
        return _frame_band(disc, result, null, sigma, measured.n_modes)
    x, ratio, quantity = _line_reading(disc, result)
    ratio = ratio / null
    sigma = np.where(_determined(disc, own), sigma, np.inf)
    trend, features, further = _features(x, ratio, sigma, measured.n_modes)
    return ProfileBand(x, ratio, sigma, trend, tuple(features), null, quantity=quantity,
                       further=tuple(further))


@dataclass(frozen=True)
class FrameProfileBand:
    """A frame's generic update read member by member: each member's :class:`ProfileBand`
    (positions along it from its start node), in member order."""

    members: tuple      # (member id, its start node, ProfileBand, "EI" or "EA")
    model_members: tuple = ()   # the frame's Members (their end nodes name a taper's ends)

    def _ranked(self, which: str) -> list:
        """(member, its start node, feature, quantity) of the members' ``which`` features
        (``"features"`` or ``"further"``), the most significant first."""
        found = [(m, start, f, what) for m, start, b, what in self.members
                 for f in getattr(b, which)]
        return sorted(found, key=lambda item: -item[2].significance)

    @property
    def features(self) -> tuple:
        """(member, its start node, feature, quantity), the most significant first (at
        most :data:`FRAME_FEATURES`)."""
        return tuple(self._ranked("features")[:FRAME_FEATURES])

    @property
    def further(self) -> tuple:
        """(member, its start node, feature, quantity) of the features beyond the band
        that :attr:`features` leaves out (beyond :data:`FRAME_FEATURES`, or beyond a
        member's three), the most significant first: said and drawn, not weighed."""
        rest = self._ranked("features")[FRAME_FEATURES:] + self._ranked("further")
        return tuple(sorted(rest, key=lambda item: -item[2].significance))

    @property
    def unexplained(self) -> tuple:
        bands = {(m, what): b for m, _, b, what in self.members}
        return tuple((m, start, f, what) for m, start, f, what in self.features
                     if f in bands[m, what].unexplained)

    @property
    def sigma(self) -> np.ndarray:
        return np.concatenate([b.sigma for _, _, b, _ in self.members])

    def explained_by(self, reading) -> "FrameProfileBand":
        """The band with each member's ``explained`` set from a reading (every member's
        nodal values, bending then axial, in member order), as :func:`explain` does a
        beam's."""
        from dataclasses import replace

        out, i = [], 0
        for m, start, b, what in self.members:
            part = reading[i:i + b.x.size] / b.null
            i += b.x.size
            rest = [f for f in b.features if not _shows(f, b.x, part, b.sigma)]
            out.append((m, start, replace(b, explained=part, unexplained=tuple(rest)), what))
        return FrameProfileBand(tuple(out), self.model_members)


#: at most this many features of a frame's generic update are read out
FRAME_FEATURES = 3


def _frame_change(f: Feature) -> float:
    """How far a feature departs from the model: a local one at its node (already held to
    :data:`FEATURE_CHANGE` by :func:`_features`), a uniform one by its level, a taper at
    its farther end.  On a frame every feature must depart by FEATURE_CHANGE, the update's
    own systematic scatter: a change of one member leaks through the joints into its
    neighbours' readings (measured, tests/test_frame_generic.py: a beam 10 % softer reads
    as 1.4-1.9 % softer columns and 4-5 % tapers, beyond their noise bands)."""
    if f.kind == "taper":
        return max(abs(f.start - 1.0), abs(f.value - 1.0))
    return abs(f.value - 1.0)


def _frame_band(disc, result, null, sigma, n_modes) -> FrameProfileBand:
    """:func:`profile_band` of a frame: each member's k_i / k_i0 against its part of the
    null profile and the band, its features read along it."""
    from .frame_generic import member_ratios

    out, i = [], 0
    model = disc.model
    for what in ("EI", "EA"):
        ratios = member_ratios(result, axial=what == "EA")
        for (member, (x, ratio)), m in zip(ratios.items(), model.members):
            part = slice(i, i + x.size)
            i += x.size
            r = ratio / null[part]
            trend, features, further = _features(x, r, sigma[part], n_modes)
            features = [f for f in features if _frame_change(f) >= FEATURE_CHANGE]
            further = [f for f in further if _frame_change(f) >= FEATURE_CHANGE]
            out.append((member, m.start, ProfileBand(x, r, sigma[part], trend,
                                                     tuple(features), null[part],
                                                     further=tuple(further)), what))
    return FrameProfileBand(tuple(out), tuple(model.members))


def noisy_copies(truth: Discretisation, measured, noise, samples: int = BAND_SAMPLES,
                 seed: int = 0) -> list:
    """``samples`` copies of ``truth``'s own modes at the sensors of ``measured`` with noise
    of the stated level (fixed seed: reproducible), as measured data: what
    :func:`profile_band` (``truth`` the model, seed 0) and :func:`explain` (``truth`` the
    fitted model, seed 1) read with the generic update.  Noisy, because the expansion
    treats noise-free data differently (its discrepancy principle smooths them by the
    stated noise): the measured data are read the same way."""
    return _copies(own_modes(truth, measured), noise, samples, seed)


def _copies(own, noise, samples, seed) -> list:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(samples):
        y = own.shapes + noise.shape * np.max(np.abs(own.shapes), axis=0) \
            * rng.standard_normal(own.shapes.shape)
        f = own.frequencies_hz * (1 + noise.freq * rng.standard_normal(own.n_modes))
        out.append(_as_measured(own, f, y))
    return out


def generic_ratio(disc: Discretisation, data, noise):
    """One draw: the generic update of ``data`` on ``disc`` as k_i / k_i0 (None if it
    fails)."""
    return _generic_ratio_of(disc, data, noise)


def draws_summary(draws, size: int):
    """The mean and spread of the draws (k_i / k_i0, ``size`` values each; failed draws
    left out)."""
    draws = [d for d in draws if d is not None]
    if len(draws) < 3:
        return np.ones(size), np.full(size, np.inf)
    centre = np.mean(draws, axis=0)
    sigma = np.std(np.array(draws) / centre, axis=0, ddof=1)
    finite = sigma[np.isfinite(sigma)]
    # six draws give σ to ±30 %: a node that happens to draw a tiny σ must not dominate
    sigma = np.maximum(sigma, 0.5 * float(np.median(finite)) if finite.size else 1e-4)
    return centre, sigma


def explain(band: ProfileBand, disc: Discretisation, fitted: Discretisation, measured,
            noise, samples: int = BAND_SAMPLES, seed: int = 1, draws=None) -> ProfileBand:
    """What the generic update would show if ``fitted`` (the model with the effect found)
    were the truth: its own modes, read like the data against the same null profile and
    band.  A feature of the data is explained when that reading shows it too.  ``draws``:
    the updates on ``disc`` of :func:`noisy_copies` ``(fitted, measured, noise, samples,
    seed)`` already run; None runs them here."""
    from dataclasses import replace

    if draws is None:
        draws = [generic_ratio(disc, c, noise)
                 for c in noisy_copies(fitted, measured, noise, samples, seed)]
    reading = typical_draw(draws, _profile_size(disc))
    if isinstance(band, FrameProfileBand):
        return band.explained_by(reading)
    explained = reading / band.null
    rest = [f for f in band.features if not _shows(f, band.x, explained, band.sigma)]
    return replace(band, explained=explained, unexplained=tuple(rest))


def typical_draw(draws, size: int) -> np.ndarray:
    """What one update typically shows: the median of the draws at each node (failed draws
    left out; fewer than 3: no change).  The data are one update, and :func:`explain` asks
    whether the fitted model's update shows what they show: a mean lets one draw that
    rings (the update of a noisy copy can swing by ±50 % where the six others agree to
    ±2 %, measured on a rising linear taper) speak for all six."""
    draws = [d for d in draws if d is not None]
    if len(draws) < 3:
        return np.ones(size)
    return np.median(draws, axis=0)


def _shows(f: Feature, x, reading, sigma) -> bool:
    """The reading deviates like feature ``f`` of the data: the same direction and at least
    half the size (at the feature's node; for a uniform change and a taper, over the nodes
    the band determines, each weighted by its band as :func:`_features` weights the data's:
    the level, or the slope of the line)."""
    use = np.isfinite(sigma) & (sigma < 10)
    if f.kind == "taper":
        t = (x[use] - x[0]) / (x[-1] - x[0])
        slope = np.polyfit(t, reading[use], 1, w=1.0 / sigma[use])[0]
        want = f.value - f.start
    elif f.kind == "uniform":
        w = 1.0 / sigma[use] ** 2
        slope, want = float(np.sum(w * reading[use]) / np.sum(w)) - 1.0, f.value - 1.0
    else:
        slope, want = float(reading[np.argmin(np.abs(x - f.x))]) - 1.0, f.value - 1.0
    return np.sign(slope) == np.sign(want) and abs(slope) >= 0.5 * abs(want)


def _determined(disc: Discretisation, measured) -> np.ndarray:
    """Nodes whose bending stiffness the measured modes determine: the mean over modes of
    (curvature at the node / the mode's largest curvature)² at least 1 %.  At a pinned or
    free end the moment, and with it what the data say about k, vanishes."""
    if disc.kind != "beam":   # (a bar is read at its elements)
        return np.ones(_profile_size(disc), dtype=bool)
    modes = vibrating_modes(disc, measured.n_modes)
    L = disc.element_length
    u = modes.shapes[disc.element_dofs()] * el.beam_dof_scaling(L)[None, :, None]
    left = np.einsum("i,eim->em", el.hermite_d2(0.0), u)
    right = np.einsum("i,eim->em", el.hermite_d2(1.0), u)
    curvature = np.zeros((len(disc.nodes), u.shape[2]))
    curvature[:-1] += 0.5 * left
    curvature[1:] += 0.5 * right
    curvature[0], curvature[-1] = left[0], right[-1]
    share = np.mean((curvature / np.max(np.abs(curvature), axis=0)) ** 2, axis=1)
    return share >= 0.01


def _features(x, ratio, sigma, n_modes):
    """A weighted straight line through the profile (its uncertainty inflated by the
    scatter about it), then the runs of nodes more than FEATURE_SIGMAS below (losses) or
    above (rises) it; a run of the other sign next to a larger one (closer than the
    resolution of n modes, length / n) is its side lobe and left out.  Returns the trend,
    the (at most) 3 most significant features, most significant first, which the diagnosis
    weighs, and the further ones beyond the band, which are said and drawn."""
    length = x[-1] - x[0]
    t = (x - x[0]) / length - 0.5
    use = np.isfinite(sigma) & (sigma < 10)
    W = 1.0 / sigma[use] ** 2
    A = np.stack([np.ones_like(t), t], 1)[use]
    cov = np.linalg.inv(A.T @ (A * W[:, None]))
    coef = cov @ (A.T @ (W * (ratio[use] - 1.0)))
    trend = 1.0 + coef[0] + coef[1] * t
    spread = max(1.0, float(np.sqrt(np.mean(((ratio - trend)[use] / sigma[use]) ** 2))))
    # m modes determine about 2m + 1 independent values of the profile; the scatter of
    # neighbouring nodes is correlated, so the line knows no more than that
    independent = min(int(np.sum(use)), 2 * n_modes + 1)
    sd = np.sqrt(np.diag(cov)) * spread * np.sqrt(np.sum(use) / max(independent, 1))
    features = []
    if abs(coef[1]) > FEATURE_SIGMAS * sd[1]:
        features.append((abs(coef[1]) / sd[1], Feature(
            "taper", x[-1], x[0], x[-1], 1 + coef[0] + coef[1] / 2, float(sd[1] / 2),
            start=1 + coef[0] - coef[1] / 2)))
    else:  # no significant slope: local features are read against a constant
        W_all = np.where(use, 1.0 / sigma**2, 0.0)
        level = float(np.sum(W_all * (ratio - 1.0)) / np.sum(W_all))
        if abs(level) > FEATURE_SIGMAS * sd[0]:
            features.append((abs(level) / sd[0], Feature(
                "uniform", 0.5 * (x[0] + x[-1]), x[0], x[-1], 1 + level, float(sd[0]))))
            trend = np.full_like(x, 1.0 + level)
        else:
            trend = np.ones_like(x)
    d = (ratio - trend) / sigma
    change = ratio / trend - 1.0
    runs = []
    for kind, mask in (("loss", (d < -FEATURE_SIGMAS) & (change < -FEATURE_CHANGE)),
                       ("rise", (d > FEATURE_SIGMAS) & (change > FEATURE_CHANGE))):
        i = 0
        while i < len(x):
            if not mask[i]:
                i += 1
                continue
            j = i
            while j + 1 < len(x) and mask[j + 1]:
                j += 1
            run = np.arange(i, j + 1)
            k = run[np.argmax(np.abs(ratio[run] - trend[run]))]
            runs.append((abs(ratio[k] - trend[k]), k, kind, i, j))
            i = j + 1
    runs.sort(reverse=True)
    resolution = length / max(n_modes, 1)
    kept = []
    for size, k, kind, i, j in runs:
        lobe = any(kk != kind and abs(x[k] - x[kk_k]) < resolution and size < s
                   for s, kk_k, kk, _, _ in kept)
        if not lobe:
            kept.append((size, k, kind, i, j))
    for _, k, kind, i, j in kept:
        features.append((abs(d[k]), Feature(kind, float(x[k]), float(x[i]), float(x[j]),
                                            float(ratio[k] / trend[k]),
                                            float(sigma[k] / trend[k]))))
    features.sort(key=lambda item: -item[0])
    features = [replace(f, significance=float(score)) for score, f in features]
    return trend, features[:3], features[3:]


#: the further features (beyond the three weighed) named one by one in the words; the
#: others are counted (a frame's 13 made one sentence of 2 000 characters)
FURTHER_SAID = 6


def describe_profile(band: ProfileBand, effect: str | None = None,
                     explains_test: bool = False) -> list[str]:
    """The generic update in words: every significant feature one sentence; with
    ``effect`` (the effect found, after :func:`explain`) which of them it explains.  When
    that effect brings the whole misfit to the noise (``explains_test``), a feature it does
    not reproduce is no evidence of anything else, and is said to be none."""
    if not band.features:
        finite = band.sigma[np.isfinite(band.sigma)]
        width = 100 * FEATURE_SIGMAS * float(np.median(finite)) if finite.size else 0.0
        what = ("bending or axial stiffness of any member" if isinstance(
            band, FrameProfileBand) else "axial stiffness" if band.quantity == "EA" else
            "bending stiffness")
        return [f"no change of the {what} beyond the noise band (±{width:.1f} %)"]
    if isinstance(band, FrameProfileBand):
        ends = {m.id: (m.start, m.end) for m in band.model_members}
        bands = {(m, what): b for m, _, b, what in band.members}

        def level(m, f, what):   # a local feature stands out from its member's level
            b = bands[m, what]
            return float(np.interp(f.x, b.x, b.trend)) if f.kind in ("loss", "rise") \
                and f.value > COLLAPSED else 1.0

        features = [((m, f, what), f"{m} (x from {start}): "
                     f"{f.describe(tuple(f'node {n}' for n in ends[m]), what, level(m, f, what))}")
                    for m, start, f, what in band.features]
        further = [f"{m}: {f.brief(what)}" for m, _, f, what in band.further]
        unexplained = [(m, f, what) for m, _, f, what in band.unexplained]
        explained = band.members[0][2].explained is not None
    else:
        features = [(f, f.describe(quantity=band.quantity)) for f in band.features]
        further = [f.brief(band.quantity) for f in band.further]
        unexplained, explained = band.unexplained, band.explained is not None
    # the further features beyond the band, which the figure shows too, in one sentence:
    # named, not weighed (the diagnosis reads the three above)
    shown = further[:FURTHER_SAID]
    more = len(further) - len(shown)
    rest = ["beyond the band too, less significant than those (not weighed; the figure "
            "labels them in grey): " + ", ".join(shown)
            + (f" and {more} more" if more else "")] if further else []
    if effect is None or not explained:
        return [text for _, text in features] + rest
    lobe = (f" (not reproduced by the fitted {effect}; with the {effect} the test fits to "
            "the noise, so this is the update's ringing, not a finding)" if explains_test
            else f" (not reproduced by the fitted {effect})")
    return [text + (lobe if f in unexplained else
                    f" (the fitted {effect}'s own modes show it too)")
            for f, text in features] + rest

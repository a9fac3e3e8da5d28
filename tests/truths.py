"""The independent truth generator (issue 21): measured modes of beams that ``gfe_opt`` did
not build, with effects built another way than the package builds them.

The package never imports this module.  Truths come from

* :class:`~tests.reference.ReferenceBeam` — its own Hermite elements on a 600-1200 element
  mesh, EI(x) and ρA(x) from plain functions, hinges (a rotational spring between the two
  sides of a node), point masses and springs, rotational end springs, tension, foundation;
* the Timoshenko closed form of a simply supported beam (shear and rotary inertia);
* :mod:`tests.continuum` — a 2-D plane-stress continuum with real geometry (scikit-fem).

and the effects are the physical things, described by what a test engineer knows, not by
the package's parameters:

* cracks by **other compliance laws** than the package's Christides–Barr zone: a hinge with
  the line-spring compliance of an edge crack (Tada's geometry function,
  :func:`line_spring_compliance`), a hinge with the Rizos polynomial, a notch of finite
  width (a short zone of the remaining depth); and the Christides–Barr law too (in family);
* zones with **smooth edges** (tanh ramps), softer and lighter, stiffer and heavier;
* **quadratic and stepped tapers** over the whole beam;
* point masses, intermediate springs, flexible clamps (end springs), a pin that gives
  (a free end on a spring), tension, a foundation, a uniform change of E;
* every support: pinned-pinned, clamped-free, clamped-clamped, clamped-pinned, free-free.

:func:`campaign` draws a fixed, seeded list of :class:`Case` objects: the starting model a
user has (a plain beam-file dict), the measured data and what is hidden (its class, place,
size).  ``scripts/bench_diagnosis.py`` runs the diagnose -> update loop on them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .reference import STEEL, ReferenceBeam, add_noise, christides_barr, product, timoshenko_ss

#: the stated noise of the issue: 0.05 % on frequencies, 0.3 % of each mode's largest value
FREQ_NOISE, SHAPE_NOISE = 0.0005, 0.003
SUPPORTS = {"pinned-pinned": ("pinned", "pinned"), "clamped-free": ("clamped", "free"),
            "clamped-clamped": ("clamped", "clamped"), "clamped-pinned": ("clamped", "pinned"),
            "free-free": ("free", "free")}
#: the package's names that are a right answer for each hidden class
ANSWERS = {
    "crack": {"crack", "section_loss"},
    "zone": {"section_loss"},
    "mass": {"point_mass"},
    "spring": {"point_spring"},
    "clamp": {"support_spring"},
    "pin_gives": {"support_translation"},
    "tension": {"axial_load"},
    "foundation": {"foundation"},
    "material": {"material"},
    "shear": {"shear"},
    "taper": {"stiffness_profile", "section_loss", "material"},
    "none": set(),
}
#: global classes: no position
GLOBAL = {"tension", "foundation", "material", "shear", "taper", "none"}


@dataclass
class Hidden:
    """One hidden effect: its class, where (m; None for a global one) and how big
    (``size``: the class's own measure, see :func:`campaign`)."""

    klass: str
    position: float | None = None
    size: dict = field(default_factory=dict)
    law: str = ""


@dataclass
class Case:
    name: str
    group: str                  # the scorecard's class: the hidden class, "pair", "continuum"
    model: dict                 # the starting model, a beam-file dict
    x: np.ndarray               # sensors [m]
    frequencies: np.ndarray     # [Hz]
    shapes: np.ndarray | None   # (sensors, modes) or None: frequencies only
    hidden: list                # [Hidden]
    stated: tuple | None        # (freq, shape) noise given to diagnose, or None (not given)
    noise_factor: float         # the data's noise over the stated level
    in_family: bool             # the package can represent the truth exactly
    signal: float = float("inf")  # χ² of the hidden effects alone (noise-free, in units of
    #                               the data's noise): below DETECTABLE the data cannot show them
    marginal: tuple = ()        # each hidden effect's own χ² with the others present (pairs:
    #                             the truth against the truth without it); () when not computed


# -------------------------------------------------------------------------------------------
# Crack laws (not the package's)
# -------------------------------------------------------------------------------------------


def tada_f(s):
    """Tada's bending geometry function of an edge crack, a/h = s (REFERENCES.md)."""
    t = np.pi * s / 2
    return np.sqrt(np.tan(t) / t) * (0.923 + 0.199 * (1 - np.sin(t)) ** 4) / np.cos(t)


def line_spring_compliance(depth_ratio, EI, h, nu=0.3):
    """Rotational compliance [rad/(N m)] of an edge crack from its strain energy release
    rate (plane strain): c = 6π(1 − ν²) h/(EI) ∫₀^α s F(s)² ds, F Tada's function."""
    s = np.linspace(1e-6, depth_ratio, 2001)
    integral = np.trapezoid(s * tada_f(s) ** 2, s)
    return 6 * np.pi * (1 - nu**2) * h / EI * integral


def rizos_compliance(depth_ratio, EI, h):
    """Rotational compliance of an edge crack by the Rizos/Dimarogonas polynomial law:
    c = 5.346 h J(α)/(EI)."""
    a = depth_ratio
    J = (1.8624 * a**2 - 3.95 * a**3 + 16.375 * a**4 - 37.226 * a**5 + 76.81 * a**6
         - 126.9 * a**7 + 172.0 * a**8 - 143.97 * a**9 + 66.56 * a**10)
    return 5.346 * h / EI * J


def smooth_zone(centre, length, ratio, edge):
    """Multiplier ``ratio`` inside a zone whose edges ramp over ``edge`` m (tanh)."""
    def f(x):
        inside = 0.5 * (np.tanh((x - centre + length / 2) / (edge / 4))
                        - np.tanh((x - centre - length / 2) / (edge / 4)))
        return 1.0 + (ratio - 1.0) * inside
    return f


# -------------------------------------------------------------------------------------------
# Drawing cases
# -------------------------------------------------------------------------------------------

BEAM = {"length": STEEL["length"], "E": STEEL["E"], "rho": STEEL["rho"], "b": STEEL["b"],
        "h": STEEL["h"], "nu": 0.3}


def model_dict(supports, elements, h=BEAM["h"], name="truth-case"):
    return {"name": name, "kind": "beam", "length": BEAM["length"], "elements": int(elements),
            "material": {"E": BEAM["E"], "rho": BEAM["rho"], "nu": BEAM["nu"]},
            "section": {"shape": "rectangle", "b": BEAM["b"], "h": float(h)},
            "supports": {"left": supports[0], "right": supports[1]}}


def _effect(klass, rng, supports, L, EI, rho_a, h, law=None):
    """(Hidden, ReferenceBeam keyword changes) of one drawn effect of ``klass``."""
    x = float(rng.uniform(0.12, 0.88) * L)
    if klass == "crack":
        law = law or str(rng.choice(["christides_barr", "line_spring", "rizos", "notch"]))
        depth = float(rng.uniform(0.25, 0.5))
        if law == "christides_barr":
            fn = christides_barr(x, depth, depth=h)
            s = np.linspace(0, L, 200001)
            compliance = float(np.trapezoid(1 / fn(s) - 1, s) / EI)
            return Hidden("crack", x, {"compliance": compliance}, law), {"rigidity": fn}
        if law == "notch":
            width = float(rng.uniform(0.002, 0.008))
            remaining = (1 - depth) ** 3
            compliance = width * (1 / remaining - 1) / EI
            return (Hidden("crack", x, {"compliance": compliance}, law),
                    {"rigidity": smooth_zone(x, width, remaining, 1e-4),
                     "mass": smooth_zone(x, width, 1 - depth, 1e-4)})
        compliance = (line_spring_compliance(depth, EI, h) if law == "line_spring"
                      else rizos_compliance(depth, EI, h))
        return (Hidden("crack", x, {"compliance": float(compliance)}, law),
                {"hinges": [(x, 1.0 / compliance)]})
    if klass == "zone":
        length = float(rng.uniform(0.06, 0.15) * L)
        stiffer = bool(rng.integers(2))
        k = float(rng.uniform(1.3, 1.8) if stiffer else rng.uniform(0.5, 0.75))
        m = float(k ** rng.uniform(0.3, 1.0))
        x = float(np.clip(x, length / 2 + 0.02 * L, L - length / 2 - 0.02 * L))
        edge = float(rng.uniform(0.05, 0.3) * length)
        return (Hidden("zone", x, {"stiffness_ratio": k, "mass_ratio": m, "length": length},
                       "smooth"),
                {"rigidity": smooth_zone(x, length, k, edge), "mass": smooth_zone(x, length, m,
                                                                                   edge)})
    if klass == "mass":
        mass = float(rng.uniform(0.03, 0.12) * rho_a * L)
        return Hidden("mass", x, {"mass": mass}), {"point_masses": [(x, mass)]}
    if klass == "spring":
        k = float(rng.uniform(0.5, 3.0) * EI * (np.pi / L) ** 3)
        return Hidden("spring", x, {"stiffness": k}), {"point_springs": [(x, k)]}
    if klass == "clamp":
        side = "left" if supports[0] == "clamped" else "right"
        k = float(rng.uniform(3.0, 30.0) * EI / L)
        return (Hidden("clamp", 0.0 if side == "left" else L, {"stiffness": k}),
                {"end_springs": {side: k}, "release": side})
    if klass == "pin_gives":
        k = float(rng.uniform(3.0, 30.0) * EI / L**3 * 10)
        return Hidden("pin_gives", L, {"stiffness": k}), {"point_springs": [(L, k)],
                                                          "free_right": True}
    if klass == "tension":
        t = float(rng.uniform(0.2, 0.6) * np.pi**2 * EI / L**2 * rng.choice([-1.0, 1.0]))
        return Hidden("tension", None, {"tension": t}), {"tension": t}
    if klass == "foundation":
        k = float(rng.uniform(0.3, 2.0) * EI * (np.pi / L) ** 4)
        return Hidden("foundation", None, {"stiffness": k}), {"foundation": k}
    if klass == "material":
        r = float(rng.uniform(0.94, 1.06))
        return Hidden("material", None, {"E_ratio": r}), {"rigidity": lambda s: r + 0 * s}
    if klass == "taper":
        if rng.integers(2):
            a = float(rng.uniform(0.15, 0.35) * rng.choice([-1, 1]))
            return (Hidden("taper", None, {"end_ratio": 1 + a}, "quadratic"),
                    {"rigidity": lambda s: 1 + a * (s / L) ** 2})
        step = float(rng.uniform(0.75, 0.9))
        return (Hidden("taper", None, {"step_ratio": step}, "stepped"),
                {"rigidity": lambda s: np.where(s > 0.5 * L, step, 1.0)})
    raise ValueError(klass)


#: which supports each class is drawn on
CLASS_SUPPORTS = {
    "crack": list(SUPPORTS), "zone": list(SUPPORTS), "mass": list(SUPPORTS),
    "spring": ["pinned-pinned", "clamped-free", "clamped-clamped", "free-free"],
    "clamp": ["clamped-free", "clamped-clamped", "clamped-pinned"],
    "pin_gives": ["pinned-pinned", "clamped-pinned"],
    "tension": ["pinned-pinned", "clamped-clamped"],
    "foundation": ["pinned-pinned", "clamped-clamped", "free-free"],
    "material": list(SUPPORTS), "taper": list(SUPPORTS), "none": list(SUPPORTS),
}


def draw(klass: str, seed: int, *, pair_with: str | None = None, frequency_only=False,
         law=None, known=None) -> Case:
    """One case of ``klass`` (a class of :data:`ANSWERS`, or "shear"), drawn from ``seed``.
    ``known``: an effect the truth and the model file both hold, ``{"effect":
    "point_mass", "position": m, "mass": kg}``, ``{"effect": "point_spring", "position":
    m, "stiffness": N/m}`` or ``{"effect": "crack", "position": m, "depth_ratio": a/d}``
    (:func:`known_campaign`); the case's other draws are as without it."""
    rng = np.random.default_rng(seed)
    L = BEAM["length"]
    if klass == "shear":
        return _shear_case(rng, seed)
    classes = [klass] + ([pair_with] if pair_with else [])
    options = set(CLASS_SUPPORTS[klass]).intersection(*(CLASS_SUPPORTS[c] for c in classes))
    if known is not None and known["effect"] in KNOWN_SUPPORTS:
        # a clamp or a pin that gives, or a preload: only on the supports that hold it
        options = {o for o in options if KNOWN_SUPPORTS[known["effect"]](SUPPORTS[o])}
    name_support = str(rng.choice(sorted(options)))
    supports = SUPPORTS[name_support]
    if known is not None and known["effect"] == "support_spring":
        known = {**known, "side": "left" if supports[0] == "clamped" else "right"}
    h = BEAM["h"]
    EI = BEAM["E"] * BEAM["b"] * h**3 / 12
    rho_a = BEAM["rho"] * BEAM["b"] * h
    hidden, each = [], []
    for c in classes:
        if c == "none":
            continue
        hid, ch = _effect(c, rng, supports, L, EI, rho_a, h, law)
        hidden.append(hid)
        each.append(ch)

    given = [] if known is None else [_known_part(known, h)]

    def truth_beam(parts):
        return ReferenceBeam(length=L, EI=EI, rho_a=rho_a, elements=800,
                             **_merge(supports, given + parts))

    beam = truth_beam(each)
    n_modes = int(rng.integers(3, 9))
    if frequency_only:
        n_modes = max(n_modes, 6)
    elements = int(rng.choice([30, 40, 46, 60]))
    between = bool(rng.integers(2))
    count = int(rng.integers(9, 46))
    x = (np.sort(rng.uniform(0.02, 0.98, count)) * L if between
         else _node_sensors(L, elements, count))
    if supports == ("free", "free") and not between:
        x = np.concatenate([[0.0], x, [L]])
    factor = float(rng.choice([1.0, 1.0, 1.5, 2.0, 3.0]))
    rigid = 2 if supports == ("free", "free") else 0
    freqs, shapes = beam.measure(n_modes + rigid, x, shape_noise=0.0, freq_noise=0.0)
    freqs, shapes = freqs[rigid:], shapes[:, rigid:]
    plain = truth_beam([])
    f0, y0 = plain.measure(n_modes + rigid, x, shape_noise=0.0, freq_noise=0.0)
    signal = _signal(freqs, shapes, f0[rigid:], y0[:, rigid:], factor, frequency_only)
    marginal = (signal,) if len(each) == 1 else ()
    if len(each) > 1:   # each effect's own χ² with the others present
        marginal = tuple(
            _signal(freqs, shapes, *(a[rigid:] if a.ndim == 1 else a[:, rigid:] for a in
                                     truth_beam(each[:i] + each[i + 1:]).measure(
                                         n_modes + rigid, x, shape_noise=0.0,
                                         freq_noise=0.0)), factor, frequency_only)
            for i in range(len(each)))
    freqs, shapes = add_noise(freqs, shapes, factor * SHAPE_NOISE, factor * FREQ_NOISE,
                              seed + 1)
    stated = (factor * FREQ_NOISE, factor * SHAPE_NOISE) if rng.integers(2) else None
    group = "pair" if pair_with else klass
    law_tag = "-" + hidden[0].law if hidden and hidden[0].law else ""
    model = model_dict(supports, elements)
    if known is not None:
        model["effects"] = [{k: (v if isinstance(v, str) else float(v))
                             for k, v in known.items()}]
        tag = {"point_mass": "", "point_spring": "spring-", "crack": "crack-",
               "support_spring": "clamp-", "support_translation": "pin-",
               "axial_load": "preload-", "foundation": "foundation-",
               "section_loss": "zone-"}[known["effect"]]
        group, law_tag = "known", f"-{tag}{klass}{law_tag}"
    return Case(f"{group}{law_tag}-{name_support}-{seed}", group, model, x, freqs,
                None if frequency_only else shapes, hidden, stated, factor,
                in_family=all(hd.law in ("", "christides_barr") for hd in hidden)
                and klass not in ("taper",), signal=signal, marginal=marginal)


def _known_part(known, h) -> dict:
    """The ReferenceBeam keywords of a known effect: a mass or a spring at its place, or a
    crack as the Christides–Barr decay of EI(x) written in the tests' own code (the
    package's ``crack`` the model file names is built by its own code)."""
    if known["effect"] == "point_mass":
        return {"point_masses": [(known["position"], known["mass"])]}
    if known["effect"] == "point_spring":
        return {"point_springs": [(known["position"], known["stiffness"])]}
    if known["effect"] == "support_spring":   # a clamp that gives: a pin and a spring
        return {"end_springs": {known["side"]: known["stiffness"]}, "release": known["side"]}
    if known["effect"] == "support_translation":   # a pin that gives: a free end on a spring
        return {"point_springs": [(BEAM["length"], known["stiffness"])], "free_right": True}
    if known["effect"] == "axial_load":
        return {"tension": known["tension"]}
    if known["effect"] == "foundation":
        return {"foundation": known["stiffness"]}
    if known["effect"] == "section_loss":   # sharp edges: a ramp of a thousandth of the zone
        edge = 1e-3 * known["length"]
        return {"rigidity": smooth_zone(known["position"], known["length"],
                                        known["stiffness_ratio"], edge),
                "mass": smooth_zone(known["position"], known["length"], known["mass_ratio"],
                                    edge)}
    return {"rigidity": christides_barr(known["position"], known["depth_ratio"], depth=h)}


def _merge(supports, parts) -> dict:
    """ReferenceBeam keywords (``supports`` included) of the effects' changes ``parts``."""
    changes = {}
    for ch in parts:
        for key, value in ch.items():
            if key in ("rigidity", "mass"):
                changes[key] = product(*(f for f in (changes.get(key), value) if f is not None))
            elif key in ("hinges", "point_masses", "point_springs"):
                changes[key] = changes.get(key, []) + value
            elif key == "end_springs":
                changes[key] = {**changes.get(key, {}), **value}
            else:
                changes[key] = value
    truth_supports = list(supports)
    if changes.pop("free_right", False):
        truth_supports[1] = "free"
    released = changes.pop("release", None)   # a clamp that gives: pinned + end spring
    if released:
        truth_supports[0 if released == "left" else 1] = "pinned"
    return {**changes, "supports": tuple(truth_supports)}


#: a hidden effect whose own χ² (noise-free) is below this cannot be told from noise by any
#: method: the 99.9 % quantile of χ²(1) with the look-elsewhere factor of 12 candidates
#: at 17 places (8 modes), 1e-3 / 204 -> 22.7 (see scripts/bench_diagnosis.py)
DETECTABLE = 22.7


def _signal(f, y, f0, y0, factor, frequency_only) -> float:
    """χ² of the difference between the truth and the plain beam (modes in order), in
    units of the data's noise; sign-aligned shapes relative to each mode's largest value."""
    chi2 = float(np.sum(((f / f0 - 1) / (factor * FREQ_NOISE)) ** 2))
    if frequency_only:
        return chi2
    scale = np.max(np.abs(y), axis=0)
    a, b = y / scale, y0 / np.max(np.abs(y0), axis=0)
    b = b * np.sign(np.sum(a * b, axis=0))
    a = a / np.linalg.norm(a, axis=0)
    b = b / np.linalg.norm(b, axis=0)
    rel = (a - b) * np.linalg.norm(y / scale, axis=0)
    return chi2 + float(np.sum((rel / (factor * SHAPE_NOISE)) ** 2))


def _node_sensors(L, elements, count):
    nodes = np.linspace(0, L, elements + 1)[1:-1]
    pick = np.unique(np.round(np.linspace(0, nodes.size - 1, min(count, nodes.size)))
                     ).astype(int)
    return nodes[pick]


def _shear_case(rng, seed) -> Case:
    """A deep simply supported beam (Timoshenko closed form), sensors between nodes or at
    them."""
    L = BEAM["length"]
    h = float(L / rng.uniform(5.0, 9.0))
    b = BEAM["b"]
    E, nu, rho = BEAM["E"], BEAM["nu"], BEAM["rho"]
    A, inertia = b * h, b * h**3 / 12
    kga = 5 / 6 * E / (2 * (1 + nu)) * A
    n_modes = int(rng.integers(3, 7))
    x = np.sort(rng.uniform(0.02, 0.98, int(rng.integers(15, 46)))) * L
    f = timoshenko_ss(n_modes, E * inertia, rho * A, rho * inertia, kga, L)
    y = np.sin(np.outer(x, np.arange(1, n_modes + 1) * np.pi / L))
    factor = float(rng.choice([1.0, 1.5, 2.0]))
    f, y = add_noise(f, y, factor * SHAPE_NOISE, factor * FREQ_NOISE, seed + 1)
    stated = (factor * FREQ_NOISE, factor * SHAPE_NOISE) if rng.integers(2) else None
    return Case(f"shear-pinned-pinned-{seed}", "shear",
                model_dict(("pinned", "pinned"), 46, h=h), x, f, y,
                [Hidden("shear", None, {"shear_rigidity": kga})], stated, factor, True)


CONTINUUM_VARIANTS = ("notch", "notch", "thinned", "doubler", "block", "roller", "none")


def continuum_case(seed: int) -> Case:
    """A 2-D plane-stress beam (tests/continuum.py) with real geometry: a double-edged
    notch, a thinned zone, a welded doubler, an attached block, a roller partway along, or
    nothing; pins at mid-height of both ends or a clamped end face with the other free."""
    from .continuum import continuum_modes

    rng = np.random.default_rng(seed)
    L, h, b = BEAM["length"], BEAM["h"], BEAM["b"]
    E, nu, rho = BEAM["E"], BEAM["nu"], BEAM["rho"]
    variant = CONTINUUM_VARIANTS[seed % len(CONTINUUM_VARIANTS)]
    cantilever = bool(rng.integers(2)) and variant != "roller"
    supports2d = ("clamp", "free") if cantilever else ("pin", "pin")
    supports = ("clamped", "free") if cantilever else ("pinned", "pinned")
    x = float(rng.uniform(0.15, 0.85) * L)
    kw, hidden = {}, []
    if variant == "notch":
        depth, width = float(rng.uniform(0.3, 0.5)), float(rng.uniform(0.001, 0.004))
        kw["notch"] = (x, width, depth)
        hidden = [Hidden("crack", x, {"compliance": width * (1 / (1 - depth) ** 3 - 1)
                                      / (E * b * h**3 / 12)}, "notch-2d")]
    elif variant in ("thinned", "doubler"):
        length = float(rng.uniform(0.06, 0.12) * L)
        ratio = float(rng.uniform(0.6, 0.8) if variant == "thinned" else rng.uniform(1.4, 2.0))
        x = float(np.clip(x, length / 2 + 0.02 * L, L - length / 2 - 0.02 * L))
        kw["thickness"] = lambda s: np.where(np.abs(s - x) <= length / 2, ratio, 1.0)
        hidden = [Hidden("zone", x, {"stiffness_ratio": ratio, "mass_ratio": ratio,
                                     "length": length}, variant)]
    elif variant == "block":
        mass = float(rng.uniform(0.05, 0.12) * rho * b * h * L)
        kw["point_mass"] = (x, mass)
        hidden = [Hidden("mass", x, {"mass": mass}, "block-2d")]
    elif variant == "roller":
        kw["supports_at"] = (x,)
        hidden = [Hidden("spring", x, {"stiffness": float("inf")}, "roller-2d")]
    n_modes = int(rng.integers(3, 7))
    count = int(rng.integers(9, 40))
    sensors = np.sort(rng.uniform(0.03, 0.97, count)) * L
    f, y = continuum_modes(L, h, b, E, nu, rho, n_modes=n_modes, sensors=sensors,
                           supports=supports2d, **kw)
    f0, y0 = continuum_modes(L, h, b, E, nu, rho, n_modes=n_modes, sensors=sensors,
                             supports=supports2d)
    factor = float(rng.choice([1.0, 1.0, 1.5, 2.0]))
    signal = _signal(f, y, f0, y0, factor, False) if hidden else 0.0
    f, y = add_noise(f, y, factor * SHAPE_NOISE, factor * FREQ_NOISE, seed + 1)
    stated = (factor * FREQ_NOISE, factor * SHAPE_NOISE) if rng.integers(2) else None
    return Case(f"continuum-{variant}-{'-'.join(supports)}-{seed}", "continuum",
                model_dict(supports, int(rng.choice([40, 46, 60]))), sensors, f, y, hidden,
                stated, factor, in_family=False, signal=signal)


#: the campaign: (class, how many, pair partner or None, frequency-only)
PLAN = [
    ("none", 14, None, False), ("material", 12, None, False), ("crack", 28, None, False),
    ("zone", 14, None, False), ("mass", 12, None, False), ("spring", 8, None, False),
    ("clamp", 10, None, False), ("pin_gives", 6, None, False), ("tension", 6, None, False),
    ("foundation", 6, None, False), ("taper", 8, None, False), ("shear", 8, None, False),
    ("crack", 4, "mass", False), ("crack", 4, "crack", False), ("zone", 3, "clamp", False),
    ("mass", 3, "material", False), ("crack", 6, None, True), ("none", 4, None, True),
    ("continuum", 14, None, False),
]


def campaign(seed: int = 2100, subset: int | None = None) -> list[Case]:
    """The fixed list of cases: :data:`PLAN`, each drawn from its own seed.  ``subset``
    keeps every n-th case of the list (a quick run with every class)."""
    cases = []
    s = seed
    for klass, count, pair, freq_only in PLAN:
        for _ in range(count):
            s += 1
            cases.append(continuum_case(s) if klass == "continuum" else
                         draw(klass, s, pair_with=pair, frequency_only=freq_only))
    return cases[::subset] if subset else cases


#: the known-effect cases (:func:`known_campaign`): (hidden class, how many), for each kind
#: of known effect
KNOWN_PLAN = [("crack", 4), ("zone", 2), ("mass", 2), ("spring", 2), ("none", 2)]
#: the known effects, in this order (each a :data:`KNOWN_PLAN` of cases; a kind added later
#: comes last, so the earlier cases keep their seeds)
KNOWN_KINDS = ("point_mass", "point_spring", "crack", "support_spring", "support_translation",
               "axial_load", "foundation", "section_loss")
#: the supports (left, right) a known effect needs: a clamp that gives a clamp, a pin that
#: gives a pin at the right end (the truth frees it onto a spring), a preload both ends held
#: along the axis as the campaign's hidden tension
KNOWN_SUPPORTS = {
    "support_spring": lambda s: "clamped" in s,
    "support_translation": lambda s: s[1] == "pinned",
    "axial_load": lambda s: s in (("pinned", "pinned"), ("clamped", "clamped")),
}


#: the known effects without a place along the beam
GLOBAL_KNOWN = ("support_spring", "support_translation", "axial_load", "foundation")


def known_campaign(seed: int = 2100, seeds=None) -> list[Case]:
    """Cases whose model file holds a known effect (in the truth too) and one hidden effect
    of :data:`KNOWN_PLAN` beside it (or none): the known effect is part of the structure
    the user modelled, not a finding, and what is hidden must be found as on a beam without
    it.  First an attached mass (a motor, a sensor block), 5–60 % of the beam's mass, then
    a spring to ground (a prop the model holds), 1–30 times EI (π/L)³ (the campaign's
    hidden springs are 0.5–3), both log-uniform, then a crack found at an earlier
    inspection and written into the file by hand (a/d uniform 0.2–0.5; in the truth the
    Christides–Barr decay of EI(x) in the tests' own code), each at 10–90 % of the
    length, then a clamp that gives (``support_spring``, 3–30 EI/L log-uniform, at the
    clamped end of supports drawn among those with a clamp; in the truth a pin with a
    rotational spring, as the campaign's hidden clamps), then a pin that gives
    (``support_translation`` at a pinned right end, 10–300 EI/L³ log-uniform; in the truth
    a free end on a spring), an axial preload (``axial_load``, ±0.1–0.6 π²EI/L², pinned or
    clamped at both ends), a foundation (0.3–3 EI (π/L)⁴ log-uniform) and a zone
    (``section_loss`` 6–15 % of the length, EI × 0.5–0.8 or 1.3–1.8, ρA × that to a power
    0.3–1, inside the beam; in the truth the tests' own zone with edges a thousandth of its
    length).  Seeds ``seed +
    1000 + i``; the known effect from its own stream, the rest of each case drawn as
    :func:`draw` draws it.  ``seeds``: only the cases of these seeds (each case draws
    from its own seed, so they are the same as in the whole list)."""
    L = BEAM["length"]
    beam_mass = BEAM["rho"] * BEAM["b"] * BEAM["h"] * L
    EI = BEAM["E"] * BEAM["b"] * BEAM["h"] ** 3 / 12
    cases, s = [], seed + 1000
    for known in KNOWN_KINDS:
        for klass, count in KNOWN_PLAN:
            for _ in range(count):
                s += 1
                if seeds is not None and s not in seeds:
                    continue
                rng = np.random.default_rng([s, 1])
                if known == "point_mass":
                    size = {"mass": beam_mass * float(np.exp(rng.uniform(np.log(0.05),
                                                                         np.log(0.6))))}
                elif known == "crack":
                    size = {"depth_ratio": float(rng.uniform(0.2, 0.5))}
                elif known == "support_spring":
                    size = {"stiffness": EI / L * float(np.exp(rng.uniform(np.log(3.0),
                                                                           np.log(30.0))))}
                elif known == "support_translation":
                    size = {"stiffness": EI / L**3 * float(np.exp(rng.uniform(np.log(10.0),
                                                                              np.log(300.0)))),
                            "side": "right"}
                elif known == "axial_load":
                    size = {"tension": float(rng.uniform(0.1, 0.6) * rng.choice([-1.0, 1.0])
                                             * np.pi**2 * EI / L**2)}
                elif known == "foundation":
                    size = {"stiffness": EI * (np.pi / L) ** 4 * float(
                        np.exp(rng.uniform(np.log(0.3), np.log(3.0))))}
                elif known == "section_loss":
                    ratio = float(rng.uniform(1.3, 1.8) if rng.integers(2)
                                  else rng.uniform(0.5, 0.8))
                    size = {"length": round(float(rng.uniform(0.06, 0.15)) * L, 4),
                            "stiffness_ratio": ratio,
                            "mass_ratio": float(ratio ** rng.uniform(0.3, 1.0))}
                else:
                    size = {"stiffness": EI * (np.pi / L) ** 3 * float(
                        np.exp(rng.uniform(0.0, np.log(30.0))))}
                place = round(float(rng.uniform(0.1, 0.9)) * L, 4)
                if known == "section_loss":   # the zone inside the beam
                    half = size["length"] / 2 + 0.02 * L
                    place = round(float(np.clip(place, half, L - half)), 4)
                at = {} if known in GLOBAL_KNOWN else {"position": place}
                cases.append(draw(klass, s, known={"effect": known, **at, **size}))
    return cases


# -------------------------------------------------------------------------------------------
# Monitoring campaigns (the batch tests and scripts/bench_batch.py)
# -------------------------------------------------------------------------------------------


def campaign_truth(i: int, n_sets: int, *, onset=0.2, final_depth=0.5, swing=0.01,
                   sets_per_day=24) -> tuple[float, float]:
    """The truth of set ``i`` of a monitoring campaign: (crack depth a/d, E factor).  No
    crack for the first ``onset`` of the sets, then a/d growing linearly to
    ``final_depth`` at the last set; E moving ±``swing`` with a daily temperature cycle."""
    start = int(round(onset * n_sets))
    depth = 0.0 if i < start else final_depth * (i - start + 1) / max(n_sets - start, 1)
    factor = 1.0 + swing * np.sin(2 * np.pi * i / sets_per_day)
    return float(depth), float(factor)


def write_campaign(model, folder, n_sets: int, *, position=0.19, n_modes=5, sensors=None,
                   shape_noise=0.003, freq_noise=0.0005, seed=0, reference_elements=400,
                   **truth_options) -> list:
    """Measured JSON files ``set-0001.json`` ... of a campaign on ``model`` (a gfe_opt
    Model: its length, section, material and supports; hourly ``time`` stamps from
    2026-01-01, ``label`` with the day and hour): each set's truth (:func:`campaign_truth`)
    is the tests' own Hermite beam (:class:`~tests.reference.ReferenceBeam`) with the crack's
    EI(x) and E scaled, not the package's model; returns the truths."""
    import json
    from datetime import datetime, timedelta
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    L = model.length
    sensors = np.linspace(0.0, L, 17)[1:-1] if sensors is None else np.asarray(sensors)
    start = datetime(2026, 1, 1)
    out = []
    for i in range(n_sets):
        depth, factor = campaign_truth(i, n_sets, **truth_options)
        crack = christides_barr(position, depth, depth=model.depth) if depth > 0 else None
        beam = ReferenceBeam(length=L, EI=model.E * model.inertia,
                             rho_a=model.rho * model.area, supports=model.supports,
                             elements=reference_elements,
                             rigidity=product(*(g for g in (crack, lambda x, f=factor: f + 0 * x)
                                                  if g is not None)))
        f, y = beam.measure(n_modes, sensors, shape_noise=shape_noise, freq_noise=freq_noise,
                            seed=seed + i)
        when = start + timedelta(hours=i)
        data = {"time": when.isoformat(timespec="minutes"),
                "label": f"day {i // 24 + 1} {when:%H}:00",
                "sensors": {"x": [float(v) for v in sensors], "dof": "w"},
                "modes": [{"frequency": float(f[j]), "shape": [float(v) for v in y[:, j]]}
                          for j in range(n_modes)]}
        (folder / f"set-{i + 1:04d}.json").write_text(json.dumps(data))
        out.append((depth, factor))
    return out

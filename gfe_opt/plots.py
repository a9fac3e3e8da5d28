"""Figures (matplotlib, an optional dependency: ``pip install gfe-opt[plot]``).

Figures are built on :class:`matplotlib.figure.Figure` directly (no pyplot, no display), so
they render headless.  Each function returns the figure; :func:`save` writes it as PNG.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _figure(width=7.0, height=3.6):
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("plots need matplotlib: pip install 'gfe-opt[plot]'") from exc
    return Figure(figsize=(width, height), layout="constrained")


def _wrapped(title: str, width: int = 90) -> str:
    """A long title (a verdict with its condition) on lines that fit a figure's width."""
    import textwrap

    return "\n".join(textwrap.wrap(title, width)) or title


def save(fig, path) -> Path:
    """Write ``fig`` as a PNG (150 dpi), atomically, and return the path."""
    from .outputs import atomic_write

    path = Path(path)
    atomic_write(path, lambda p: fig.savefig(p, dpi=150, format="png"))
    return path


def parameter_changes(curves, *, quantity: str, title: str, crack_position=None):
    """Percentage change of a nodal quantity along the beam, one curve per mesh.

    ``curves`` is a list of ``(label, x, change_pct)``; the paper's Figs. 1-4.
    """
    fig = _figure()
    ax = fig.add_subplot()
    markers = "osd^v<>"
    for i, (label, x, change) in enumerate(curves):
        ax.plot(x, change, marker=markers[i % len(markers)], ms=3, lw=1, label=label)
    if crack_position is not None:
        ax.axvline(crack_position, color="0.5", ls=":", lw=1, label="crack")
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel(quantity)
    ax.set_title(title)
    ax.legend(fontsize=8)
    return fig


def profile_with_band(band, label=None, *, length=None, supports=("pinned", "pinned"),
                      places=(), findings=(), elsewhere=()):
    """The generic update's k_i / k_i0 along the structure with its ±3σ noise band, the
    features beyond it labelled, and, when an effect was found, what the update reads
    from that effect's own modes; below, the structure with the located place and the
    fitted effects (``findings`` and ``elsewhere`` as for :func:`structure_sketch`)."""
    fig = _figure(7.0, 4.6 if length is not None else 3.6)
    if length is not None:
        ax, sketch = fig.subplots(2, 1, sharex=True, height_ratios=(3.4, 1.1))
    else:
        ax, sketch = fig.add_subplot(), None
    _profile_panel(ax, band, label, quantity=band.quantity)
    _legend_below(fig, ax)
    ax.set_title("Bending stiffness read from the test at each node, over the model's"
                 if band.quantity == "EI" else
                 "Axial stiffness read from the test at each element, over the model's",
                 fontsize=10)
    if sketch is not None:
        structure_sketch(sketch, length, supports, places=places, findings=findings,
                         elsewhere=elsewhere)
        sketch.set_xlabel("x [m]")
    else:
        ax.set_xlabel("x [m]")
    return fig


def frame_profiles(band, label=None):
    """A frame's generic update (:class:`~gfe_opt.realisation.FrameProfileBand`): each
    member's k_i / k_i0 along it from its start node, with its ±3σ noise band and, when an
    effect was found, the same reading of that effect's own modes; one panel a member."""
    bending = [m for m in band.members if m[3] == "EI"]
    axial = {m[0]: m for m in band.members if m[3] == "EA"}
    ends = {m.id: (m.start, m.end) for m in band.model_members}
    fig = _figure(9.0, 1.0 + 2.2 * len(bending))
    axes = np.atleast_2d(fig.subplots(len(bending), 2, squeeze=False))
    for row, (member, start, b, _) in zip(axes, bending):
        a, e = ends.get(member, (start, "?"))
        for ax, what, part in ((row[0], "EI", b), (row[1], "EA", axial[member][2])):
            # the frame's weighed features (at most three in all) in black, as the words
            weighed = [f for m, _, f, q in band.features if m == member and q == what]
            _profile_panel(ax, part, label, quantity=what, weighed=weighed)
            ax.set_title(f"{member}: {what}, from node {a} to node {e}", fontsize=9)
            ax.set_xlabel(f"distance from node {a} [m]", fontsize=8)
    _legend_below(fig, axes[0][0])
    fig.suptitle("Bending (EI) and axial (EA) stiffness read from the test at each node of "
                 "each member, over the model's", fontsize=10)
    return fig


def _legend_below(fig, ax):
    """``ax``'s legend under the figure, where it covers no curve and no label (inside the
    axes it covered the labels of the deepest features)."""
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=3,
               fontsize=7, frameon=False)


def _profile_panel(ax, band, label, quantity="EI", weighed=None):
    """k_i / k_i0 (``quantity`` "EA": EA_i / EA_i0) of one
    :class:`~gfe_opt.realisation.ProfileBand` on ``ax``; ``weighed``: the features of it
    the diagnosis weighs, where not all of ``band.features`` (a frame member's)"""
    from .realisation import COLLAPSED

    x = band.x
    ok = np.isfinite(band.sigma)
    ax.fill_between(x[ok], (1 - 3 * band.sigma)[ok], (1 + 3 * band.sigma)[ok], color="0.87",
                    label="what noise alone gives (±3σ)")
    ax.plot(x, band.ratio, "o-", ms=3, color="tab:blue", label="generic update of the test")
    if band.explained is not None:
        ax.plot(x, band.explained, "--", color="tab:red",
                label=f"the same, of the fitted {label}'s modes")
    for f in (*band.features, *band.further):
        if f.kind not in ("loss", "rise"):
            continue
        # grey: not reproduced by the effect found, or beyond the band but not weighed
        # (the further features, :attr:`~gfe_opt.realisation.ProfileBand.further`)
        grey = (f in band.further or (weighed is not None and f not in weighed)
                or (f in band.unexplained and band.explained is not None))
        text = "collapsed" if f.value <= COLLAPSED else f"{f.value:.2f}±{f.sigma:.2g}"
        # at the curve: a local value is read against the profile's level (its trend)
        at = f.value * float(np.interp(f.x, band.x, band.trend))
        ax.annotate(text, (f.x, at), textcoords="offset points",
                    xytext=(0, -12 if f.kind == "loss" else 6), ha="center", fontsize=7,
                    color="0.45" if grey else "black")
    ax.axhline(1.0, color="0.4", lw=0.8)
    ax.margins(y=0.12)
    ax.set_ylabel("$k_i / k_{i,0}$ (1 = as modelled)" if quantity == "EI" else
                  "$EA_i / EA_{i,0}$ (1 = as modelled)")


def disturbance_function(x_nodes, q_identified, x_fine, q_exact, *, label_exact: str):
    """The paper's Fig. 5: identified Q_i at the nodes (circles) and Q(x) (solid)."""
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot(x_fine, q_exact, "-", lw=1.2, label=label_exact)
    ax.plot(x_nodes, q_identified, "o", mfc="none", label="identified $Q_i = 1 + Δk_i/k_0$")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("Q")
    ax.set_ylim(min(0.0, float(np.min(q_identified)) - 0.05),
                max(1.1, float(np.max(q_identified)) + 0.05))
    ax.set_title("Disturbance function: exact (solid), identified (circles)")
    ax.legend(fontsize=8)
    return fig


def mac_matrix(mac, pairs=()):
    """MAC heat map, test modes down and model modes across, with the values in the cells.
    Only the model modes up to the highest paired one (or best match of a test mode) are
    drawn: the rest are computed to pair against, and would fill the figure with zeros."""
    mac = np.asarray(mac)
    pairs = set(pairs)
    # up to the highest paired model mode, and each test mode's best match (an unpaired
    # test mode's best model mode must stay visible)
    best = [int(np.argmax(row)) for row in mac] if mac.size else []
    shown = max([j for _, j in pairs] + best, default=mac.shape[1] - 1) + 1
    shown = min(max(shown, mac.shape[0]), mac.shape[1])
    cropped = mac[:, :shown]
    fig = _figure(1.6 + 0.6 * shown, 1.0 + 0.5 * mac.shape[0])
    ax = fig.add_subplot()
    image = ax.imshow(cropped, vmin=0.0, vmax=1.0, cmap="viridis")
    for (i, j), value in np.ndenumerate(cropped):
        ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=7,
                color="black" if value > 0.6 else "white",
                fontweight="bold" if (i, j) in pairs else "normal")
    ax.set_xticks(range(shown), [str(j + 1) for j in range(shown)])
    ax.set_yticks(range(mac.shape[0]), [str(i + 1) for i in range(mac.shape[0])])
    more = f" (of {mac.shape[1]} computed)" if shown < mac.shape[1] else ""
    ax.set_xlabel(f"model mode{more}")
    ax.set_ylabel("test mode")
    ax.set_title("MAC: 1 = same shape (pairs in bold)", fontsize=10)
    fig.colorbar(image, ax=ax, shrink=0.8, label="MAC")
    return fig


def paired_frequencies(pairs):
    """Test and model frequencies of the pairs (log scale: modes spread over decades) and
    the model's error in % per pair, signed and labelled."""
    fig = _figure(7.0, 3.4)
    left, right = fig.subplots(1, 2)
    modes = [p.test_mode for p in pairs]
    left.semilogy(modes, [p.test_hz for p in pairs], "o-", label="test")
    left.semilogy(modes, [p.model_hz for p in pairs], "s--", mfc="none", label="model")
    left.set_xlabel("test mode")
    left.set_ylabel("frequency [Hz]")
    left.set_xticks(modes)
    left.legend(fontsize=8)
    left.set_title("Paired frequencies", fontsize=10)
    errors = [p.error_pct for p in pairs]
    colours = ["tab:red" if e > 0 else "tab:blue" for e in errors]
    right.bar(modes, errors, color=colours)
    for m, e in zip(modes, errors):
        right.annotate(f"{e:+.2f}", (m, e), textcoords="offset points",
                       xytext=(0, 3 if e >= 0 else -10), ha="center", fontsize=7)
    right.axhline(0.0, color="0.5", lw=0.8)
    right.set_xticks(modes)
    right.set_xlabel("test mode")
    right.set_ylabel(r"$(f_\mathrm{model} - f_\mathrm{test}) / f_\mathrm{test}$ [%]")
    right.set_title("Model error (red: model higher, blue: lower)", fontsize=10)
    right.margins(y=0.15)
    return fig


def structure_sketch(ax, length, supports=("pinned", "pinned"), *, sensors=None, places=(),
                     findings=(), elsewhere=(), deciding=()):
    """The structure as a bar on ``ax`` (x in m): its supports, the sensors, where the model
    fails (``places``: (x, share of the largest residual)), ``findings``: (effect type,
    model, parameters, σ[, parameters on a bound]) each drawn by the effect's own ``mark``,
    and, hollow with "or", where an effect fits as well (``elsewhere``: (x, effect name),
    the diagnosis's caveats), and where one more sensor would tell them apart
    (``deciding``: x, the caveats' decisions)."""
    ax.plot([0, length], [0, 0], lw=6, color="0.4", solid_capstyle="butt")
    if sensors is not None and len(sensors):
        ax.plot(sensors, np.zeros_like(np.asarray(sensors, float)), "|", color="white",
                ms=5, mew=1, label="sensors")
    for end, kind in zip((0.0, length), supports):
        ax.annotate(kind, (end, 0), textcoords="offset points", xytext=(0, -16),
                    ha="center", fontsize=7)
    for k, (x, _) in enumerate(places):  # the largest labelled, the others marked
        ax.plot([x], [-0.35], marker="^", color="tab:purple", ms=9 if k == 0 else 5,
                alpha=1.0 if k == 0 else 0.6)
        if k == 0:
            ax.annotate(f"model fails most: x = {x:.3f} m", (x, -0.35),
                        textcoords="offset points", xytext=(0, -12), ha="center", fontsize=7,
                        color="tab:purple")
    for k, (effect, model, params, sigma, *bounds) in enumerate(findings):  # a pair: 2 levels
        effect.mark(ax, model, params, sigma, 0.35 + 0.5 * k, *bounds)
    found_at = [effect.position(params) for effect, _, params, *_ in findings]
    raised = 0
    for k, (x, name) in enumerate(elsewhere):
        ax.plot([x], [0.35], marker="o", ms=9, mfc="none", mec="0.3", mew=1.2)
        # above a finding's own label where the two labels would meet (a label of ~25
        # characters spans about a fifth of the bar), each such one a line above the last
        near = any(isinstance(f, (int, float)) and abs(f - x) < 0.2 * length
                   for f in found_at)
        ax.annotate(f"or {name} here (fits as well)" if k == 0 else f"or {name}", (x, 0.35),
                    textcoords="offset points", xytext=(0, 20 + 10 * raised if near else 8),
                    ha="center", fontsize=7, color="0.3")
        raised += near
    for k, x in enumerate(deciding):
        ax.plot([x], [-0.35], marker="v", ms=8, mfc="none", mec="tab:blue", mew=1.2)
        ax.annotate("a sensor here would decide" if k == 0 else "", (x, -0.35),
                    textcoords="offset points", xytext=(0, -12), ha="center", fontsize=7,
                    color="tab:blue")
    ax.set_yticks([])
    ax.set_ylim(-1.2, 1.2)
    ax.set_xlim(-0.04 * length, 1.04 * length)
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)


def localisation(x, residual, comac, length, supports=("pinned", "pinned"), places=()):
    """Where the model fails: the residual force (high is bad) and the COMAC (1 is good) on
    axes of their own, the structure below with the sensors and the located places."""
    fig = _figure(7.0, 5.0)
    top, middle, bottom = fig.subplots(3, 1, sharex=True, height_ratios=(3, 1.6, 1.2))
    top.plot(x, residual / max(np.max(residual), 1e-300), "o-", ms=3, color="tab:purple")
    top.set_ylabel("residual force\n(largest = 1)")
    top.set_ylim(-0.05, 1.1)
    if len(places):
        top.axvline(places[0][0], color="tab:purple", lw=0.8, ls=":")
    top.set_title("Where the model fails: high residual force = the model's equations of "
                  "motion do not hold", fontsize=9)
    middle.plot(x, comac, "s-", ms=3, color="tab:green")
    middle.set_ylabel("COMAC\n(1 = shapes agree)")
    low = float(np.min(comac)) if len(comac) else 0.0
    middle.set_ylim(min(low, 0.9) - 0.02, 1.01)
    structure_sketch(bottom, length, supports, sensors=x, places=places)
    bottom.set_xlabel("x [m]")
    return fig


def candidate_errors(fits, baseline_pct, together=None, verdict=None, *, length=None,
                     supports=("pinned", "pinned"), findings=(), elsewhere=(), note=None,
                     deciding=()):
    """Frequency error left by each candidate effect (significant ones coloured) and, when
    a pair is suggested, by the pair (hatched, on top); with ``findings`` and ``elsewhere``
    (as for :func:`structure_sketch`) and the ``length``, the structure with them below;
    ``note`` (what the diagnosis did not name for its share) above the bars."""
    sketch = None
    if findings and length is not None:
        fig = _figure(7.0, 4.4)
        ax, sketch = fig.subplots(2, 1, height_ratios=(3.2, 1.0))
    else:
        fig = _figure(7.0, 3.2)
        ax = fig.add_subplot()
    names = [f.effect for f in fits]
    values = [f.misfit.freq_error_rms_pct for f in fits]
    # the effect found (the first significant one) green, others also significant pale
    colours = ["tab:green" if f.significant and i == 0 else "#a6d8a6" if f.significant
               else "0.6" for i, f in enumerate(fits)]
    hatches = [""] * len(fits)
    if together is not None:
        names.insert(0, " + ".join(e.name for e in together.effects[-2:]))
        values.insert(0, together.misfit.freq_error_rms_pct)
        colours.insert(0, "tab:green")
        hatches.insert(0, "//")
    bars = ax.barh(names[::-1], values[::-1], color=colours[::-1])
    for bar, hatch in zip(bars, hatches[::-1]):
        bar.set_hatch(hatch)
    ax.axvline(baseline_pct, color="tab:red", ls="--", lw=1, label="model as it stands")
    ax.set_xlabel("frequency error left [% rms]")
    for bar, value in zip(bars, values[::-1]):
        ax.annotate(f"{value:.3g} %", (value, bar.get_y() + bar.get_height() / 2),
                    textcoords="offset points", xytext=(3, 0), va="center", fontsize=7)
    ax.set_title(("" if note is None else note + "\n")
                 + "best first; green: the effect found, pale green: significant but not "
                 "the answer", fontsize=8)
    if verdict:
        fig.suptitle(_wrapped(f"verdict: {verdict}"), fontsize=10, fontweight="bold")
    ax.legend(fontsize=8)
    if sketch is not None:
        structure_sketch(sketch, length, supports, findings=findings, elsewhere=elsewhere,
                         deciding=deciding)
        sketch.set_xlabel("x [m]: the effects found")
    return fig


def error_history(steps):
    """Frequency error after each step, ``steps`` a list of ``(label, error_pct)``."""
    fig = _figure(6.0, 3.2)
    ax = fig.add_subplot()
    labels = [s[0] for s in steps]
    ax.bar(labels, [s[1] for s in steps], color="tab:blue")
    for i, (_, value) in enumerate(steps):
        ax.text(i, value, f"{value:.3f} %", ha="center", va="bottom", fontsize=8)
    ax.set_ylabel("frequency error [% rms]")
    ax.set_title("Error before and after each added effect")
    return fig


def nodal_coefficients(realisations, bending_rigidity=None, length=None):
    """The continuous-equation coefficients read at each node, one quantity per panel: the
    stiffness and mass ratios (1 = the model's), the axial force T and the foundation
    stiffness k_f, each against the scale that would matter physically (the Euler load
    π²EI/L², and EI(π/L)⁴, the foundation that doubles f₁² of a pinned beam) when the
    bending rigidity and length are given."""
    fig = _figure(7.0, 5.4)
    top, middle, bottom = fig.subplots(3, 1, sharex=True)
    x = [r.x for r in realisations]
    top.plot(x, [r.k_ratio for r in realisations], "o-", ms=3,
             label="$k/k_0$: coefficient of $w''''$ (raw; read against the noise in "
                   "stiffness_change.png)")
    top.plot(x, [r.mass_ratio for r in realisations], "s-", ms=3,
             label=r"$m/m_0$: coefficient of $\ddot w$")
    top.axhline(1.0, color="0.5", lw=0.8)
    top.set_ylabel("ratio to the model")
    top.legend(fontsize=7)
    top.set_title(r"What each node's updated equation says: "
                  r"$(k\,w'')'' - T\,w'' + k_f\,w + m\,\ddot w = 0$", fontsize=10)
    middle.plot(x, np.array([r.tension for r in realisations]) / 1e3, "o-", ms=3,
                color="tab:brown")
    middle.set_ylabel("axial force\n$T$ [kN]")
    bottom.plot(x, np.array([r.foundation for r in realisations]) / 1e6, "s-", ms=3,
                color="tab:olive")
    bottom.set_ylabel("foundation\n$k_f$ [MN/m²]")
    if bending_rigidity is not None and length is not None:
        euler = np.pi**2 * bending_rigidity / length**2 / 1e3
        double = bending_rigidity * (np.pi / length) ** 4 / 1e6
        for ax, scale, text in ((middle, euler, r"± Euler load $\pi^2EI/L^2$"),
                                (bottom, double, r"± $EI(\pi/L)^4$ (doubles $f_1^2$)")):
            for sign in (1, -1):
                ax.axhline(sign * scale, color="0.5", ls="--", lw=0.8,
                           label=text if sign > 0 else None)
            ax.legend(fontsize=7, loc="upper right")
    from .realisation import uniform_term

    for ax, values, unit, scale in (
            (middle, [r.tension for r in realisations], "kN", 1e3),
            (bottom, [r.foundation for r in realisations], "MN/m²", 1e6)):
        ax.axhline(0.0, color="0.7", lw=0.8)
        level = uniform_term(values)
        if not np.any(np.abs(values) > 0):
            text = "zero at every node"
        elif level:
            text = f"one value along the beam: {level / scale:.4g} {unit}"
        else:
            text = ("no value common to the beam: node-to-node scatter (k'' and noise), "
                    "not a physical term")
        ax.text(0.01, 0.9, text, transform=ax.transAxes, fontsize=7, color="0.3", va="top",
                bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    bottom.set_xlabel("x [m]")
    return fig


def frame_nodal_coefficients(members):
    """A frame's :func:`nodal_coefficients`: each member's interior nodes read in its own
    axes (:class:`~gfe_opt.realisation.MemberRealisation`), one curve a member against the
    distance from its start node over its length: k/k0 and EA/EA0, the axial force T beyond
    the model's, the foundation k_f beyond the model's; each member whose T or k_f holds one
    value along it is named with that value."""
    from .realisation import uniform_term

    many = len(members) > 3   # the legend beside the panels, not over the curves
    fig = _figure(9.5 if many else 7.0, 5.8)
    top, middle, bottom = fig.subplots(3, 1, sharex=True)
    from matplotlib import rcParams

    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    for i, m in enumerate(members):
        colour = colours[i % len(colours)]
        s = [r.x / m.length for r in m.rows]
        top.plot(s, [r.k_ratio for r in m.rows], "o-", ms=2.5, color=colour,
                 label=f"{m.member} (from {m.start}): $k/k_0$")
        top.plot(s, m.axial_ratio, "--", lw=1.0, color=colour,
                 label=f"{m.member}: $EA/EA_0$")
        middle.plot(s, np.array([r.tension for r in m.rows]) / 1e3, "o-", ms=2.5,
                    color=colour)
        bottom.plot(s, np.array([r.foundation for r in m.rows]) / 1e6, "s-", ms=2.5,
                    color=colour)
    top.axhline(1.0, color="0.5", lw=0.8)
    top.set_ylabel("ratio to the model")
    if many:
        fig.legend(*top.get_legend_handles_labels(), fontsize=6, loc="outside right upper")
    else:
        top.legend(fontsize=6, ncol=2)
    top.set_title("What each member node's updated equation says, in the member's axes:\n"
                  r"$(k\,w'')'' - T\,w'' + k_f\,w + m\,\ddot w = 0$ across it, "
                  r"$-(EA\,u')' + m\,\ddot u = 0$ along it", fontsize=9)
    middle.set_ylabel("axial force\n$T$ [kN]")
    bottom.set_ylabel("foundation\n$k_f$ [MN/m²]")
    weakest = min(members, key=lambda m: m.euler_load)
    for sign in (1, -1):
        middle.axhline(sign * weakest.euler_load / 1e3, color="0.5", ls="--", lw=0.8,
                       label=(f"± {weakest.member}'s Euler load $\\pi^2EI/\\ell^2$ (the "
                              "members' lowest)") if sign > 0 else None)
    middle.legend(fontsize=7, loc="lower right")
    for ax, key, unit, scale in ((middle, "tension", "kN", 1e3),
                                 (bottom, "foundation", "MN/m²", 1e6)):
        ax.axhline(0.0, color="0.7", lw=0.8)
        lines = []
        for m in members:
            values = [getattr(r, key) for r in m.rows]
            level = uniform_term(values)
            if level:
                lines.append(f"{m.member}: one value along it, {level / scale:.4g} {unit}")
        if not lines:
            any_value = any(getattr(r, key) for m in members for r in m.rows)
            lines = ["no value common to any member: node-to-node scatter (k'' and noise), "
                     "not a physical term" if any_value else "zero at every node"]
        ax.text(0.01, 0.9, "\n".join(lines), transform=ax.transAxes, fontsize=7,
                color="0.3", va="top", bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    bottom.set_xlabel("distance from the member's start node / its length")
    return fig


def stabilisation(identification):
    """Stabilisation chart: stable poles per model order over the summed FRF magnitude, the
    modes kept marked."""
    ident = identification
    fig = _figure(7.0, 4.0)
    ax = fig.add_subplot()
    frfs = ident.frfs
    band = (frfs.freq >= ident.band[0]) & (frfs.freq <= ident.band[1])
    magnitude = np.sum(np.abs(frfs.frf[:, band]), axis=0)
    ax2 = ax.twinx()
    ax2.semilogy(frfs.freq[band], magnitude, color="0.6", lw=0.8)
    ax2.set_ylabel(f"Σ|FRF| ({frfs.form})", color="0.4")
    orders = np.arange(1, len(ident.stable) + 1)
    for order, poles in zip(orders, ident.stable):
        ax.plot(poles, np.full(len(poles), order), "+", color="tab:blue", ms=4, mew=0.8)
    ax.plot([], [], "+", color="tab:blue", label="stable pole (Δf < 0.1 %, Δζ < 5 %)")
    for k, f in enumerate(ident.measured.frequencies_hz):
        ax.axvline(f, color="tab:red", lw=0.8, ls="--",
                   label="identified mode" if k == 0 else None)
    ax.set_xlim(ident.band)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model order")
    ax.set_zorder(ax2.get_zorder() + 1)
    ax.patch.set_visible(False)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.06, 1.0))  # off mode 1
    ax.set_title("Stabilisation chart (LSCF)")
    return fig


def trend_parameters(trend):
    """Each fitted parameter against time/label with its ±σ band; the first set where an
    effect becomes significant marked."""
    keys = list(trend.parameters)
    fig = _figure(7.5, max(2.2, 1.9 * len(keys)) if keys else 2.5)
    if not keys:
        ax = fig.add_subplot()
        ax.text(0.5, 0.5, "no fitted parameter in the table", ha="center", va="center")
        ax.set_axis_off()
        return fig
    axes = fig.subplots(len(keys), 1, sharex=True, squeeze=False)[:, 0]
    x = trend.x
    for ax, key in zip(axes, keys):
        values, sigmas = trend.parameters[key]
        ax.plot(x, values, color="tab:blue", lw=1.2, marker="." if len(x) < 60 else None)
        band = np.isfinite(sigmas)
        if np.any(band):
            lower = np.where(band, values - sigmas, np.nan)
            upper = np.where(band, values + sigmas, np.nan)
            ax.fill_between(x, lower, upper, color="tab:blue", alpha=0.25, lw=0,
                            label="±1 σ")
        finite = values[np.isfinite(values)]
        if finite.size:  # the values set the scale; a set with a huge σ does not
            typical = np.nanmedian(sigmas[band]) if np.any(band) else 0.0
            pad = 0.1 * (finite.max() - finite.min()) + 2 * typical + 1e-12 * abs(finite).max()
            ax.set_ylim(finite.min() - pad, finite.max() + pad)
        effect = key.split(".")[0]
        for onset in trend.onsets:
            if onset.effect == effect:
                ax.axvline(x[onset.index], color="tab:red", ls="--", lw=1,
                           label=f"significant from {onset.when}")
        place = trend.places.get(effect)
        ax.set_ylabel(_parameter_label(key) + (f"\n{place}" if place else ""), fontsize=8)
        ax.grid(alpha=0.3)
        handles, _ = ax.get_legend_handles_labels()
        if handles:
            ax.legend(fontsize=7, loc="best")
    axes[0].set_title(f"Fitted parameters over {len(x)} sets")
    _trend_axis(axes[-1], trend)
    return fig


def _parameter_label(key: str) -> str:
    """``crack.position`` -> ``crack\nposition [m]`` (the unit from the effect's
    parameter; ``crack#2.position`` for a repeated effect)."""
    from .effects import EFFECTS

    effect, _, name = key.partition(".")
    kind = EFFECTS.get(effect.split("#")[0])
    unit = next((p.unit for p in (kind.parameters if kind else ()) if p.name == name), None)
    suffix = f" [{unit}]" if unit and unit != "-" else ""
    return f"{effect}\n{name.replace('_', ' ')}{suffix}"


def trend_errors(trend):
    """Frequency error before and after the fit of each set."""
    fig = _figure(7.5, 2.8)
    ax = fig.add_subplot()
    ax.plot(trend.x, trend.errors_before, color="tab:red", lw=1.2, label="before")
    ax.plot(trend.x, trend.errors_after, color="tab:green", lw=1.2, label="after")
    ax.set_ylabel("frequency error [% rms]")
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title("Frequency error of each set, before and after the fit")
    _trend_axis(ax, trend)
    return fig


def _trend_axis(ax, trend):
    if trend.axis == "time":
        ax.set_xlabel("time")
        ax.figure.autofmt_xdate()
    elif trend.axis == "number":
        ax.set_xlabel("time")
    else:
        ax.set_xlabel("set")
        if len(trend.ticks) <= 20:
            ax.set_xticks(trend.x, trend.ticks, rotation=30, ha="right", fontsize=7)


def _frame_axes(ax, members, color="0.75", lw=1.0):
    for xy in members:
        ax.plot(xy[:, 0], xy[:, 1], color=color, lw=lw)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def frame_modes(members, member_nodes, xy, shapes, points, directions, titles):
    """Paired modes drawn on a frame: the undeformed members (grey), the model's mode
    (blue, mesh nodes moved by its u, v scaled to the test) and the measured displacement
    at each sensor (red arrows along the sensor's direction), one panel a pair."""
    n = len(shapes)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig = _figure(4.0 * cols, 3.6 * rows)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    span = float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1])))
    for ax, (u, v, y), title in zip(axes, shapes, titles):
        peak = max(float(np.max(np.abs(np.concatenate([u, v])))), float(np.max(np.abs(y))))
        k = 0.12 * span / peak if peak > 0 else 0.0
        _frame_axes(ax, members)
        for nodes in member_nodes:
            ax.plot(xy[nodes, 0] + k * u[nodes], xy[nodes, 1] + k * v[nodes], color="C0",
                    lw=1.6)
        ax.quiver(points[:, 0], points[:, 1], k * y * directions[:, 0],
                  k * y * directions[:, 1], angles="xy", scale_units="xy", scale=1,
                  color="C3", width=0.006)
        ax.set_title(title, fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    axes[0].plot([], [], color="C0", label="model")
    axes[0].plot([], [], color="C3", label="test (sensors)")
    axes[0].legend(fontsize=7, loc="best")
    return fig


def frame_localisation(members, points, residual, worst, labels):
    """The frame with each sensor coloured by its shape residual (rms over the pairs, in
    each mode's largest amplitude); the largest ones named."""
    fig = _figure(6.4, 4.6)
    ax = fig.subplots()
    _frame_axes(ax, members, color="0.55", lw=1.5)
    # sensors at one point (two directions): the point shows the larger residual
    keys = [tuple(np.round(p, 9)) for p in points]
    top = {}
    for i, k in enumerate(keys):
        if k not in top or residual[i] > residual[top[k]]:
            top[k] = i
    shown = np.array(sorted(top.values(), key=lambda i: residual[i]))
    sc = ax.scatter(points[shown, 0], points[shown, 1], c=residual[shown], cmap="viridis",
                    s=46, zorder=3, edgecolors="k", linewidths=0.4)
    fig.colorbar(sc, ax=ax, shrink=0.8, label="shape residual (of the largest amplitude)")
    for label in worst:
        i = labels.index(label)
        ax.annotate(label, points[i], fontsize=7, xytext=(4, 4), textcoords="offset points")
    ax.margins(0.15)
    ax.set_title("where the measured shapes differ from the model's", fontsize=10)
    return fig


#: how each effect found is marked on a frame: marker and colour (an axial stiffness or
#: load is its member drawn over in colour)
FRAME_MARKS = {"crack": ("X", "tab:red"), "joint_spring": ("o", "tab:orange"),
               "support_spring": ("D", "tab:brown"), "support_translation": ("D", "tab:brown"),
               "point_mass": ("s", "tab:purple"), "point_spring": ("^", "tab:green"),
               "attached_body": ("p", "tab:purple"), "rotary_inertia": ("P", "tab:purple"),
               "axial_stiffness": (None, "tab:blue"),
               "axial_load": (None, "tab:cyan"), "foundation": (None, "tab:olive"),
               "shear": ("*", "tab:pink"), "stiffness_profile": (None, "goldenrod"),
               "member_shear": (None, "tab:pink"), "mass_profile": (None, "tab:purple")}


def frame_findings(members, marks, failing, title, caveats=(), elsewhere=(), deciding=()):
    """A frame diagnosis drawn on the frame (grey): the effects found, each numbered at its
    place (``marks``: (effect name, (x, y), label, member polyline or None)) and listed
    with its values below, then ``caveats`` (sentences, in grey: what the data do not
    decide) and, hollow with "or", the places where an effect fits as well (``elsewhere``,
    as ``marks``), the sensors where the model as it stands fails most (``failing``:
    ((x, y), label), hollow circles) and where one more sensor would tell the finding from
    what fits as well (``deciding``: ((x, y), label), the caveats' decisions, hollow
    triangles); titled with the verdict."""
    import textwrap

    wrapped = [textwrap.fill(c, 105) for c in caveats]   # (120 ran past a 6.4 in figure)
    below = [(f"{i}: {label}", FRAME_MARKS.get(name, ("*", "tab:green"))[1], 8)
             for i, (name, _, label, _) in enumerate(marks, 1)] or [("no effect found", "k", 8)]
    below += [(c, "0.35", 7) for c in wrapped]
    lines = max(sum(text.count("\n") + 1 for text, _, _ in below), 1)
    fig = _figure(6.4, 4.4 + 0.22 * lines)
    ax, listing = fig.subplots(2, 1, height_ratios=(4.4, 0.22 * lines))
    listing.set_axis_off()
    _frame_axes(ax, members, color="0.6", lw=1.5)
    for i, ((x, y), label) in enumerate(failing):
        ax.scatter([x], [y], s=140, facecolors="none", edgecolors="0.25", linewidths=1.2,
                   zorder=3, label="where the model as it stands fails most" if i == 0 else None)
        ax.annotate(label, (x, y), fontsize=6.5, color="0.25", xytext=(0, -13),
                    textcoords="offset points", ha="center")
    for i, (name, (x, y), _, line) in enumerate(marks, 1):
        marker, colour = FRAME_MARKS.get(name, ("*", "tab:green"))
        if line is not None:
            ax.plot(line[:, 0], line[:, 1], color=colour, lw=4, alpha=0.7, zorder=2)
        if marker is not None:
            ax.scatter([x], [y], marker=marker, s=90, color=colour, zorder=4,
                       edgecolors="k", linewidths=0.5)
        ax.annotate(str(i), (x, y), fontsize=9, color=colour, fontweight="bold",
                    xytext=(7, 5), textcoords="offset points", zorder=5)
    for name, (x, y), _, line in elsewhere:
        marker, colour = FRAME_MARKS.get(name, ("*", "tab:green"))
        if line is not None:
            ax.plot(line[:, 0], line[:, 1], color=colour, lw=4, alpha=0.3, ls=":", zorder=2)
        ax.scatter([x], [y], marker=marker or "o", s=90, facecolors="none",
                   edgecolors=colour, linewidths=1.2, zorder=4)
        ax.annotate(f"or {name}", (x, y), fontsize=7, color=colour, xytext=(7, -10),
                    textcoords="offset points", zorder=5)
    for i, ((x, y), label) in enumerate(deciding):
        ax.scatter([x], [y], marker="v", s=80, facecolors="none", edgecolors="tab:blue",
                   linewidths=1.2, zorder=4,
                   label="one more sensor here would decide (the notes below)" if i == 0
                   else None)
        ax.annotate(label, (x, y), fontsize=6.5, color="tab:blue", xytext=(0, -14),
                    textcoords="offset points", ha="center")
    if elsewhere:   # one legend entry for them all, whatever their markers
        ax.scatter([], [], marker="o", s=90, facecolors="none", edgecolors="0.3",
                   linewidths=1.2, label='hollow, "or": fits as well (the notes below)')
    row = 0
    for text, colour, size in below:
        listing.text(0.0, 1.0 - row / lines, text, fontsize=size, color=colour, va="top",
                     transform=listing.transAxes)
        row += text.count("\n") + 1
    entries = sum(map(bool, (failing, elsewhere, deciding)))
    if entries:   # above the frame, the title above it
        ax.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), frameon=False)
    ax.margins(0.12)
    ax.set_title(_wrapped(title), fontsize=10, fontweight="bold", loc="left",
                 pad=6 + 11 * entries)
    return fig

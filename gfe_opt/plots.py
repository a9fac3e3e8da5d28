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


def profile_with_band(band, label=None):
    """The generic update's k_i / k_i0 along the structure with its ±3σ noise band and, when
    an effect was found, what the update reads from that effect's own modes."""
    fig = _figure()
    ax = fig.add_subplot()
    x = band.x
    ok = np.isfinite(band.sigma)
    ax.fill_between(x[ok], (1 - 3 * band.sigma)[ok], (1 + 3 * band.sigma)[ok], color="0.85",
                    label="noise band (±3σ)")
    ax.plot(x, band.ratio, "o-", ms=3, color="tab:blue", label="generic update of the data")
    if band.explained is not None:
        ax.plot(x, band.explained, "--", color="tab:red",
                label=f"... of the fitted {label}'s modes")
    ax.axhline(1.0, color="0.4", lw=0.8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("$k_i / k_{i,0}$")
    ax.set_title("Generic-element update: nodal bending stiffness over the model's")
    ax.legend(fontsize=8)
    return fig


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
    """MAC heat map (test modes down, model modes across) with the values in the cells."""
    mac = np.asarray(mac)
    fig = _figure(1.0 + 0.55 * mac.shape[1], 1.0 + 0.5 * mac.shape[0])
    ax = fig.add_subplot()
    image = ax.imshow(mac, vmin=0.0, vmax=1.0, cmap="viridis")
    for (i, j), value in np.ndenumerate(mac):
        ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=7,
                color="black" if value > 0.6 else "white",
                fontweight="bold" if (i, j) in set(pairs) else "normal")
    ax.set_xticks(range(mac.shape[1]), [str(j + 1) for j in range(mac.shape[1])])
    ax.set_yticks(range(mac.shape[0]), [str(i + 1) for i in range(mac.shape[0])])
    ax.set_xlabel("model mode")
    ax.set_ylabel("test mode")
    ax.set_title("MAC (pairs in bold)")
    fig.colorbar(image, ax=ax, shrink=0.8)
    return fig


def paired_frequencies(pairs):
    """Test and model frequencies of the pairs, and their errors in %."""
    fig = _figure(7.0, 3.4)
    left, right = fig.subplots(1, 2)
    modes = [p.test_mode for p in pairs]
    left.plot(modes, [p.test_hz for p in pairs], "o-", label="test")
    left.plot(modes, [p.model_hz for p in pairs], "s--", label="model")
    left.set_xlabel("test mode")
    left.set_ylabel("frequency [Hz]")
    left.legend(fontsize=8)
    right.bar(modes, [p.error_pct for p in pairs], color="tab:red")
    right.axhline(0.0, color="0.5", lw=0.8)
    right.set_xlabel("test mode")
    right.set_ylabel("Δf [%]")
    right.set_title("model − test")
    return fig


def localisation(x, residual, comac, length, supports=("pinned", "pinned")):
    """Residual force and COMAC along the structure, with the structure drawn below."""
    fig = _figure(7.0, 4.2)
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    top.plot(x, residual / max(np.max(residual), 1e-300), "o-", ms=3, label="residual force")
    top.plot(x, comac, "s-", ms=3, label="COMAC")
    top.set_ylabel("relative value")
    top.set_ylim(-0.05, 1.1)
    top.legend(fontsize=8)
    top.set_title("Where the model fails")
    bottom.plot([0, length], [0, 0], lw=6, color="0.4", solid_capstyle="butt")
    bottom.plot(x, np.zeros_like(x), "v", color="tab:blue", ms=4, label="sensors")
    for end, kind in zip((0.0, length), supports):
        bottom.annotate(kind, (end, 0), textcoords="offset points", xytext=(0, -14),
                        ha="center", fontsize=7)
    bottom.set_yticks([])
    bottom.set_ylim(-1, 1)
    bottom.set_xlabel("x [m]")
    return fig


def candidate_errors(fits, baseline_pct, together=None):
    """Frequency error left by each candidate effect (significant ones coloured) and, when
    a pair is suggested, by the pair (hatched, on top)."""
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
    ax.set_title("Candidate effects, best first (green: the effect found; pale green: also "
                 "significant)", fontsize=9)
    ax.legend(fontsize=8)
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


def nodal_coefficients(realisations):
    """The continuous-equation coefficients per node (k/k0, m/m0, tension, foundation)."""
    fig = _figure(7.0, 4.0)
    top, bottom = fig.subplots(2, 1, sharex=True)
    x = [r.x for r in realisations]
    top.plot(x, [r.k_ratio for r in realisations], "o-", ms=3, label="k / k0 (w'''')")
    top.plot(x, [r.mass_ratio for r in realisations], "s-", ms=3, label="m / m0 (ẅ)")
    top.legend(fontsize=8)
    top.set_title("Continuous equation at each node")
    bottom.plot(x, [r.tension for r in realisations], "o-", ms=3, label="T [N] (−T w'')")
    bottom.plot(x, [r.foundation for r in realisations], "s-", ms=3, label="k_f [N/m²] (w)")
    bottom.set_xlabel("x [m]")
    bottom.legend(fontsize=8)
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
    ax.legend(fontsize=8, loc="upper left")
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
        ax.set_ylabel(key.replace("_", " "), fontsize=8)
        ax.grid(alpha=0.3)
        handles, _ = ax.get_legend_handles_labels()
        if handles:
            ax.legend(fontsize=7, loc="best")
    axes[0].set_title(f"Fitted parameters over {len(x)} sets")
    _trend_axis(axes[-1], trend)
    return fig


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

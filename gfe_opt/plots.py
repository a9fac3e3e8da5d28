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
    """Write ``fig`` as a PNG (150 dpi) and return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
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


def disturbance_function(x_nodes, q_identified, x_fine, q_exact, *, label_exact: str):
    """The paper's Fig. 5: identified Q_i at the nodes (circles) and Q(x) (solid)."""
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot(x_fine, q_exact, "-", lw=1.2, label=label_exact)
    ax.plot(x_nodes, q_identified, "o", mfc="none", label="identified $Q_i = 1 + Δk_i/k_0$")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("Q")
    ax.set_ylim(min(0.0, float(np.min(q_identified)) - 0.05), 1.1)
    ax.set_title("Disturbance function: exact (solid), identified (circles)")
    ax.legend(fontsize=8)
    return fig

"""What the diagnosis asks of a structure, one interface for a straight beam or bar
(:class:`Line`) and a plane frame (:class:`Frame`) (issue 24, item 2: one code path).

The diagnosis (:mod:`gfe_opt.diagnosis`) runs the same steps on both; where the two differ
it asks :func:`structure` of its model, and the difference lives here:

* **places**: along a line an effect's place is a position, fitted like any other
  variable; on a frame it is also a member or a joint, chosen from a list
  (:attr:`Line.discrete_places`): each member is a group of starts of its own, fitted
  as a job of its own, and the places that fit about as well are reported;
* **sensors**: a line's sensors lie at positions x, read through one sensor matrix kept for
  the whole diagnosis; a frame's are read through its mesh, per model (a joint spring gives
  a member's end its own rotation), so the matrix is None here;
* **neighbours** for the whiteness test: in order along the line; along each direction's
  chain of sensors on a frame;
* **where the model fails**: x along the line; a sensor on a frame;
* **spans** of a profile: the line; each member of a frame;
* **the generic-element update**: of the line's elements; member by member on a frame;
* **a test's file**: a CSV's translations are a beam's w or a bar's u; a frame's own
  formats name each sensor's place and direction.
"""

from __future__ import annotations

import numpy as np

from .assembly import discretise
from .errors import GfeSolverError

__all__ = ["Frame", "Line", "structure"]

#: the generic update's failures that leave a diagnosis without it (not an error)
GENERIC_FAILURES = (GfeSolverError, ValueError, np.linalg.LinAlgError)


def structure(model) -> Line | Frame:
    """The interface of ``model``: :class:`Frame` for a plane frame, else :class:`Line`."""
    return Frame(model) if model.kind == "frame" else Line(model)


class Line:
    """A straight beam or bar: places are positions along it, sensors at x."""

    #: a place is a position only (fitted); a frame's is also a member or a joint (chosen)
    discrete_places = False
    #: shapes too sparse for the whiteness test alone (:func:`diagnosis.sparse_shapes`)
    sparse_shapes = False

    def __init__(self, model):
        self.model = model

    def load_measured(self, path):
        """The measured modes in ``path`` for this model (a CSV's translations are the
        beam's w, the bar's u)."""
        from .measured import load_measured

        return load_measured(path, dof="w" if self.model.kind == "beam" else "u")

    def prepared(self, measured, *, units: bool = False):
        """``(measured, dropped, C)``: the test on the model (sensors outside it dropped,
        with notes), its size checked (and its units, with ``units``), and its sensor
        matrix."""
        from .correlation import check_model_size, check_units
        from .measured import on_model

        model = self.model
        measured, dropped = on_model(measured, model)
        check_model_size(discretise(model), measured, model.source or model.name)
        if units:
            check_units(model, measured)
        return measured, dropped, self.sensor_matrix(measured)

    def sensor_matrix(self, measured):
        """The sensors' reading of the model's DOFs (one for every fit of the diagnosis)."""
        from .measured import sensor_matrix

        model = self.model
        return sensor_matrix(model.nodes, model.kind, measured.x, measured.dof,
                             measured.source)

    def neighbours(self, measured):
        """``(order, a, b)``: the sensors' order along the structure (None: as given), and
        the neighbouring pairs ``a[i]``, ``b[i]`` in that order."""
        n = measured.n_sensors
        return np.argsort(measured.x), np.arange(1, n), np.arange(0, max(n - 1, 0))

    def failure_places(self, measured, noise) -> list:
        """Where the model fails, largest first: ``(x, fraction)``."""
        from .correlation import compare

        return compare(self.model, measured, noise=max(noise.shape, 1e-3)).failure_places()

    def hint(self, places) -> float:
        """Where along the structure a local effect starts, x / L: the largest failure."""
        return places[0][0] / self.model.length if places else 0.5

    def start_hint(self, measured, noise) -> float:
        """:meth:`hint` of the places where the model fails (``update``: none fitted yet)."""
        return self.hint(self.failure_places(measured, noise))

    def fraction(self, position, member=None) -> float | None:
        """``position`` as a fraction of its span (None where no position is given)."""
        if not isinstance(position, (int, float)):
            return None
        return position / self.model.length

    def spans(self, members=None) -> list[tuple]:
        """``(member, length)`` of each span a profile lies along: the line (member None)."""
        return [(None, self.model.length)]

    def generic_update(self, measured, noise, disc=None):
        """The paper's generic-element update of the measured data (may raise;
        ``disc``: the model's discretisation, if built)."""
        from .updating import update_generic

        disc = discretise(self.model) if disc is None else disc
        return update_generic(disc, measured, noise=max(noise.shape, 1e-3))

    def generic_band(self, measured, noise):
        """The generic update's stiffness profile read against its noise band
        (:func:`~gfe_opt.realisation.profile_band`; None where the update fails, and on a
        bar: its profile is EA's, which no start of a stiffness profile reads)."""
        if self.model.kind != "beam":
            return None
        from .realisation import profile_band

        disc = discretise(self.model)
        try:
            result = self.generic_update(measured, noise, disc)
        except GENERIC_FAILURES:
            return None
        return profile_band(disc, measured, result, noise) if result.ok else None

    def realise(self, generic) -> list | None:
        """The generic update read node by node in words (None on a bar)."""
        if not generic.ok or self.model.kind != "beam":
            return None
        from .realisation import realise

        return realise(generic.discretisation, discretise(self.model))

    # -- compare: pairs, MAC, where the model fails ------------------------------------
    #: the figures ``compare --plot`` writes
    @property
    def compare_figures(self) -> tuple:
        from .names import COMPARE_FIGURES

        return COMPARE_FIGURES

    def compare(self, measured, *, mac_threshold=None, noise=None):
        """Paired modes, frequency errors, MAC and where the model fails
        (:func:`~gfe_opt.correlation.compare`: the residual forces of the measured shapes
        expanded on the model, regularised by the relative shape ``noise``)."""
        from .correlation import DEFAULT_MAC_THRESHOLD, DEFAULT_SHAPE_NOISE, compare

        return compare(self.model, measured,
                       mac_threshold=DEFAULT_MAC_THRESHOLD if mac_threshold is None
                       else mac_threshold,
                       noise=DEFAULT_SHAPE_NOISE if noise is None else noise)

    def headline(self, measured) -> str:
        """The first line ``compare`` prints: the model and the test."""
        model = self.model
        return (f"{model.name}: {model.kind}, {model.elements} elements, "
                f"{measured.n_modes} measured modes at {measured.n_sensors} sensors")

    def format_comparison(self, result) -> str:
        """The comparison as text (pairs, then where the model fails)."""
        from .text import format_comparison

        return format_comparison(result, self.model.length)

    def comparison_figures(self, result, measured) -> dict:
        """The figures of a comparison, by file name."""
        from .report import compare_figures

        return compare_figures(result, self.model)

    def comparison_report(self, report, result, measured) -> None:
        """The comparison's section of an HTML report."""
        model = self.model
        report.heading("Comparison")
        report.paragraph(f"{model.name}: {model.kind}, {model.elements} elements; "
                         f"{measured.n_modes} measured modes at {measured.n_sensors} "
                         "sensors.")
        report.table(["mode", "f_test [Hz]", "f_model [Hz]", "Δf %", "MAC"],
                     [[p.test_mode, f"{p.test_hz:.2f}", f"{p.model_hz:.2f}",
                       f"{p.error_pct:+.2f}", "—" if p.mac is None else f"{p.mac:.3f}"]
                      for p in result.pairs])
        mac = "" if result.mac_mean is None else f", mean MAC {result.mac_mean:.3f}"
        report.paragraph(f"Frequency error {result.freq_error_rms_pct:.2f} % rms{mac}.")
        report.paragraph("; ".join(result.notes))
        for x, rel in result.failure_places():
            report.paragraph(f"The model fails near x = {x:.3f} m "
                             f"({100 * rel:.0f} % of the largest residual force).")

    def diagnosis_figures(self, diagnosis) -> dict:
        """The figures of a diagnosis, by file name, drawn along the line."""
        from .report import line_diagnosis_figures

        return line_diagnosis_figures(diagnosis, self.model)

    # -- modes: the model's modes written as a test ---------------------------------------
    def write_modes(self, n_modes: int, out, *, force: bool = False, protect=()) -> list[str]:
        """Write the model's ``n_modes`` lowest elastic modes to ``out`` as a measured file
        (the translations at the nodes: a beam's w, a bar's u); returns the lines
        ``gfe-opt modes`` prints."""
        from .errors import GfeInputError
        from .inputs import MAX_SENSORS
        from .measured import make_measured, save_measured
        from .modal import discretisation_modes, rigid_body_count

        model = self.model
        if len(model.nodes) > MAX_SENSORS + 2:  # a value at every node (supports may drop two)
            raise GfeInputError("--out", str(out), f"would hold shapes at {len(model.nodes)} "
                                f"nodes, above the {MAX_SENSORS} sensors a measured file may "
                                "have: use a model of fewer elements for a measured file")
        disc = discretise(model)
        rigid = rigid_body_count(disc)
        if n_modes + rigid > len(disc.free) - 1:
            raise GfeInputError("--modes", None, f"the model has {len(disc.free) - 1 - rigid} "
                                f"elastic modes at most, asked for {n_modes}")
        modes = discretisation_modes(disc, n_modes + rigid)
        elastic = modes.frequencies_hz > 0  # measured modes vibrate: rigid-body ones left out
        per = model.dofs_per_node
        shapes = modes.shapes[::per][:, elastic]  # translations at the nodes
        keep = np.any(shapes != 0, axis=1)
        save_measured(make_measured(model.nodes[keep], "w" if model.kind == "beam" else "u",
                                    modes.frequencies_hz[elastic], shapes[keep], model.name),
                      out, force=force, protect=protect)
        lines = [f"{int(elastic.sum())} modes of {model.name} at {int(keep.sum())} nodes "
                 f"written to {out}"]
        if rigid:
            lines.append(f"note: {rigid} rigid-body mode{'s' if rigid > 1 else ''} (0 Hz) left "
                         "out: a test measures vibration")
        return lines

    def check_repeats(self, effects, where: str) -> None:
        """At most one instance of a global effect."""
        from .model import check_repeats

        check_repeats(effects, where, "effects")

    def mirror_symmetric(self) -> bool:
        """Equal supports and no local effect: an effect at x and at L − x fit alike."""
        from .effects import effect_type

        model = self.model
        return model.supports[0] == model.supports[1] and not any(
            effect_type(e.name).local for e in model.effects)

    def first_place(self, kind) -> dict:
        """The fixed parameters of an effect's first place (none: a position is fitted)."""
        return {}

    def check_member(self, effect) -> None:
        """An effect to add needs no member."""


class Frame(Line):
    """A plane frame: places are a member (and a position along it) or a joint, chosen;
    sensors are read through the mesh, per model."""

    discrete_places = True
    sparse_shapes = True

    def load_measured(self, path):
        from .frame_data import load_frame_measured

        return load_frame_measured(path, self.model)

    def prepared(self, measured, *, units: bool = False):
        from .correlation import check_model_size

        model = self.model
        check_model_size(discretise(model), measured, model.source or model.name)
        return measured, [], None

    def sensor_matrix(self, measured):
        return None   # read through the mesh, per model (fitting.evaluate)

    def neighbours(self, measured):
        from .frame_data import neighbour_pairs

        a, b = neighbour_pairs(self.model, measured.sensors)
        return None, a, b

    def failure_places(self, measured, noise) -> list:
        """Where the model fails, largest first: ``(sensor, fraction)``."""
        from .frame_data import compare_frame

        return compare_frame(self.model, measured).failure_places()

    def hint(self, places) -> float:
        return 0.5   # a frame's effects start on every member, not at one place

    def start_hint(self, measured, noise) -> float:
        return 0.5   # (no comparison needed)

    def fraction(self, position, member=None) -> float | None:
        if not isinstance(position, (int, float)) or member is None:
            return None
        model = self.model
        return position / model.member_length(model.member(member))

    def spans(self, members=None) -> list[tuple]:
        model = self.model
        return [(m.id, model.member_length(m)) for m in model.members
                if members is None or m.id in members]

    def generic_update(self, measured, noise):
        from .frame_generic import update_frame_generic

        return update_frame_generic(self.model, measured, noise=max(noise.shape, 1e-3))

    def generic_band(self, measured, noise):
        return None

    def realise(self, generic) -> list | None:
        if not generic.ok:
            return None
        from .realisation import realise_members

        return realise_members(generic.discretisation, discretise(self.model))

    @property
    def compare_figures(self) -> tuple:
        from .names import FRAME_COMPARE_FIGURES

        return FRAME_COMPARE_FIGURES

    def compare(self, measured, *, mac_threshold=None, noise=None):
        """Paired modes, frequency errors, MAC and each sensor's shape residual
        (:func:`~gfe_opt.frame_data.compare_frame`; nothing is expanded, so ``noise``
        does not enter)."""
        from .frame_data import compare_frame

        return compare_frame(self.model, measured, mac_threshold=mac_threshold)

    def headline(self, measured) -> str:
        model = self.model
        shapes = (f"at {len(measured.sensors)} sensors" if measured.shapes is not None
                  else "(frequencies only)")
        return (f"{model.name}: frame, {len(model.members)} members, {model.n_elements} "
                f"elements, {measured.n_modes} measured modes {shapes}")

    def format_comparison(self, result) -> str:
        from .text import format_frame_comparison

        return format_frame_comparison(result)

    def comparison_figures(self, result, measured) -> dict:
        from .frame_data import frame_figures

        return frame_figures(result, self.model, measured)

    def comparison_report(self, report, result, measured) -> None:
        report.heading("Comparison")
        report.preformatted(self.format_comparison(result))

    def diagnosis_figures(self, diagnosis) -> dict:
        """The figures of a diagnosis, drawn on the frame."""
        from .report import frame_diagnosis_figures

        return frame_diagnosis_figures(diagnosis, self.model)

    def write_modes(self, n_modes: int, out, *, force: bool = False, protect=()) -> list[str]:
        """The frame's modes at its sensors' places (:func:`~gfe_opt.frame.write_frame_modes`:
        x and y at the nodes and along the members)."""
        from .frame import write_frame_modes

        model = self.model
        written, sensors, rigid = write_frame_modes(model, n_modes, out, force=force,
                                                    protect=protect)
        lines = [f"{written} modes of {model.name} ({len(model.members)} members, "
                 f"{model.n_elements} elements) at {sensors} sensors written to {out}"]
        if rigid:
            lines.append(f"note: {rigid} rigid-body mode{'s' if rigid > 1 else ''} (0 Hz) left "
                         "out")
        return lines

    def check_repeats(self, effects, where: str) -> None:
        """One joint spring a member end, one axial load a member."""
        from .frame import check_repeats

        check_repeats(effects, where)

    def mirror_symmetric(self) -> bool:
        return False   # a frame's symmetry is not an end-for-end mirror

    def first_place(self, kind) -> dict:
        return (kind.starts(self.model, 0.5) or [{}])[0]

    def check_member(self, effect) -> None:
        from .errors import GfeInputError

        if effect.parameters.get("member") is None:
            raise GfeInputError("--add", effect.name, f"a {effect.name} on a frame needs its "
                                f"member: --add {effect.name}:member=ID")


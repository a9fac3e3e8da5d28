r"""What measurement would tell two models apart that fit the test alike.

When the diagnosis says the data cannot tell a finding from an alternative (a caveat of kind
``alike``, the turning body on a frame included, ``places`` on a frame, or ``undecided``),
the engineer's next question is what to measure.  Both models
are fitted to the same test, so at its sensors they read alike; elsewhere they need not.
:func:`deciding_measurement` predicts, from the two models themselves, the reading of one
more sensor at every place of a grid over the structure (a beam: :data:`BEAM_PLACES`
places along it, the test's direction; a frame: :data:`MEMBER_PLACES` places along each
member, in x and in y) and the frequencies of the next modes, each in units of the test's
own noise (a test of frequencies alone: the next modes only):

* a sensor at place p: the square root of the χ² that model a would gain, over the modes
  the test paired in both, if model b were right and the test had the sensor at p: the
  residual's own scaling (each shape to unit length over the sensors, the new one
  included, so that its reading also rescales the others) and noise (σ_s times the largest
  reading), with b's shapes standing for the data; less a's χ² against b's shapes
  without it;
* the next mode k (above those measured): :math:`|f_{a,k} / f_{b,k} - 1| / σ_f`.

The separation is said in σ with the place (or mode) where it is largest.  It tells the
two models apart when its square exceeds :data:`~gfe_opt.diagnosis.ALIKE_CHI2` noise floors
(the diagnosis's threshold, √(ALIKE_CHI2 × floor)), the χ² gap under which the diagnosis
calls two fits alike: a reading that moves their χ² further apart than that would make the
diagnosis choose.  Where no place and no next mode does, that is said instead, with the
best σ (the σ needed only in the JSON: it follows the noise floor, and with it the
arithmetic).  A prediction of the two fits as they stand, not of the structure, and before
either is refitted with the new reading: refitted, they may move closer (the portal's body
of ``scripts/study_frame_body.py`` case 9201 needed the sensor said, then the one said
next).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: places along a beam where one more sensor is tried (every 0.5 % of the length)
BEAM_PLACES = 201
#: places along each member of a frame where one more sensor is tried (both directions)
MEMBER_PLACES = 41
#: the next modes above those measured whose frequencies are compared
NEXT_MODES = 3


@dataclass(frozen=True)
class Decision:
    """The measurement that best tells two models apart: ``sensor`` (a beam: ``{"x": m,
    "dof": ...}``; a frame: a sensor of the frame contract) with ``sensor_sigma``, and the
    next mode ``mode`` (1-based, counted from the first elastic mode; None when none was
    computed) at
    ``mode_hz`` with ``mode_sigma``; ``threshold`` the σ that decides."""

    sensor: dict | None
    sensor_sigma: float
    mode: int | None
    mode_hz: float | None
    mode_sigma: float
    threshold: float

    @property
    def sensor_decides(self) -> bool:
        return self.sensor is not None and bool(self.sensor_sigma > self.threshold)

    @property
    def mode_decides(self) -> bool:
        return self.mode is not None and bool(self.mode_sigma > self.threshold)

    @property
    def decides(self) -> bool:
        return self.sensor_decides or self.mode_decides

    def as_dict(self) -> dict:
        """The ``decide`` object of a caveat in ``diagnose --json`` (README, Diagnosis)."""
        return {"sensor": self.sensor, "sensor_sigma": round(float(self.sensor_sigma), 3),
                "mode": self.mode,
                "mode_hz": None if self.mode_hz is None else float(self.mode_hz),
                "mode_sigma": round(float(self.mode_sigma), 3),
                "threshold_sigma": round(float(self.threshold), 3),
                "decides": bool(self.decides)}

    def words(self) -> str:
        """The clause a caveat ends with."""
        parts = []
        if self.sensor_decides:
            parts.append(f"a sensor {_place_words(self.sensor)} would see them differ by "
                         f"{self.sensor_sigma:.1f} σ of the shape noise")
        if self.mode_decides:
            hz = float(f"{self.mode_hz:.4g}")   # 4 digits, no exponent (18870 Hz)
            parts.append(f"mode {self.mode} (about {hz:g} Hz) would differ by "
                         f"{self.mode_sigma:.1f} σ in frequency")
        if parts:
            return (" or ".join(parts) + " (the two fits' prediction as they stand: refitted "
                    "with the new reading they may move closer)")
        best = max(self.sensor_sigma, self.mode_sigma)
        what = (f"no one more sensor and none of the next {NEXT_MODES} modes"
                if self.sensor is not None else
                f"none of the next {NEXT_MODES} modes' frequencies")
        # (the σ needed, :attr:`threshold`, is in the JSON: it follows the noise floor,
        # which a candidate ending in another valley under other arithmetic moves)
        return f"{what} would tell them apart (at best {best:.1f} σ)"


def _place_words(sensor: dict) -> str:
    if "member" in sensor:
        return (f"on {sensor['member']} at {sensor['position']:.4g} m, direction "
                f"{sensor['direction']}")
    return f"at x = {sensor['x']:.4g} m"


def deciding_measurement(model_a, model_b, measured, noise, threshold: float,
                         C=None) -> Decision | None:
    """The :class:`Decision` between two models fitted to ``measured`` (module docstring);
    None where either cannot be evaluated.  A test of frequencies alone: the next modes
    only (``sensor`` None: one more sensor reads no shape where none was measured)."""
    from .fitting import evaluate

    a = evaluate(model_a, measured, noise, C)
    b = evaluate(model_b, measured, noise, C)
    if a is None or b is None:
        return None
    sensor, sensor_sigma = None, 0.0
    if not measured.frequency_only and len(a.rows) and len(b.rows):
        places, probe = _grid(model_a, measured)
        ca, cb = a.disc.observation(probe), b.disc.observation(probe)
        total = np.zeros(len(places))
        for i, (row, ja) in enumerate(zip(a.rows, a.cols)):
            both = np.flatnonzero(b.rows == row)
            if not both.size:   # (a mode one of them leaves unpaired: its χ² says so)
                continue
            total += _sensor_terms(a, b, i, int(both[0]), ca @ a.modes.shapes[:, ja],
                                   cb @ b.modes.shapes[:, b.cols[both[0]]], noise)
        k = int(np.argmax(total))
        sensor, sensor_sigma = places[k], float(np.sqrt(total[k]))
    mode, mode_hz, mode_sigma = _next_mode(a, b, noise)
    return Decision(sensor, sensor_sigma, mode, mode_hz, mode_sigma, threshold)


def _sensor_terms(a, b, i, ib, at_a, at_b, noise):
    """Mode i's (of a; ib of b) part of the χ² gap between the two models that one more
    sensor opens, at each place (``at_a``, ``at_b``: the modes there), where model b is
    right: model a's residual over the test's sensors and the new one, the shapes of both
    to unit length over all of them (the residual's own scaling) and its noise σ_s times
    the largest reading, less its residual without the new sensor."""
    sa, sb = a.sign[i] * a.shat[:, i], b.sign[ib] * b.shat[:, ib]   # unit at the sensors
    pa, pb = a.sign[i] * at_a / a.norm[i], b.sign[ib] * at_b / b.norm[ib]
    na, nb = np.sqrt(1.0 + pa**2), np.sqrt(1.0 + pb**2)
    diff = sa[:, None] / na[None, :] - sb[:, None] / nb[None, :]
    new = np.sum(diff**2, axis=0) + (pa / na - pb / nb) ** 2
    scale = noise.shape * np.maximum(np.max(np.abs(sb)), np.abs(pb)) / nb
    old = np.sum((sa - sb) ** 2) / (noise.shape * np.max(np.abs(sb))) ** 2
    return np.maximum(new / scale**2 - old, 0.0)


def _grid(model, measured):
    """(places, a test with a sensor at each and no readings) of :func:`deciding_measurement`."""
    if model.kind == "frame":
        places = [{"member": m.id, "position": float(round(t * model.member_length(m), 6)),
                   "direction": d}
                  for m in model.members for t in np.linspace(0.0, 1.0, MEMBER_PLACES)
                  for d in ("x", "y")]
        probe = replace(measured, sensors=places,
                        shapes=np.zeros((len(places), measured.n_modes)))
        return places, probe
    x = np.linspace(0.0, model.length, BEAM_PLACES)
    probe = replace(measured, x=x, shapes=np.zeros((x.size, measured.n_modes)))
    return [{"x": float(v), "dof": measured.dof} for v in x], probe


def _next_mode(a, b, noise):
    """(mode, its frequency in model a, σ) of the elastic mode above the paired ones whose
    frequency the two models set furthest apart (of :data:`NEXT_MODES`); modes counted
    from the first elastic one."""
    fa, fb = a.modes.frequencies_hz, b.modes.frequencies_hz
    rigid = int(np.sum(fa <= 0))
    start = int(max(np.max(a.cols), np.max(b.cols))) + 1 if len(a.cols) and len(b.cols) else 0
    best = (None, None, 0.0)
    for k in range(max(start, rigid), min(start + NEXT_MODES, fa.size, fb.size)):
        if fa[k] <= 0 or fb[k] <= 0:
            continue
        sigma = abs(fa[k] / fb[k] - 1.0) / noise.freq
        if sigma > best[2]:
            best = (k + 1 - rigid, float(fa[k]), float(sigma))
    return best

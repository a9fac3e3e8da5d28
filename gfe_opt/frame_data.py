"""Measured modes of plane frames (issue 24, contract) and their comparison with a frame model.

JSON::

    {"sensors": [{"node": "B", "direction": "x"},
                 {"member": "beam", "position": 0.25, "direction": "y"}, ...],
     "modes": [{"frequency": Hz, "shape": [one value per sensor]}, ...]}

``direction`` is ``"x"``, ``"y"`` or an angle in degrees from x (counter-clockwise); a
member sensor's ``position`` is in metres from the member's start node.  A sensor between
mesh nodes reads the member's element shape functions (linear along the member, cubic
Hermite across it), rotated into the frame's axes.  A frequency-only file has no
``sensors`` and no ``shape``.

CSV (``#`` starts a comment line)::

    x,y,direction,<f1 Hz>,<f2 Hz>,...
    <x m>,<y m>,<direction>,<value mode 1>,<value mode 2>,...

one row per sensor: the point's coordinates in the frame's axes (placed on the frame as a
UFF node is, :func:`locate`) and its direction as in JSON; the header row alone is a test
of frequencies only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .correlation import PairSummary
from .errors import GfeInputError, GfeSolverError
from .frame import (
    FrameDiscretisation,
    FrameMesh,
    FrameModel,
    frame_mesh,
    frame_modes,
    has_shear,
    rotations,
)
from .measured import ModeCounts, time_and_label


@dataclass(frozen=True)
class FrameMeasured(ModeCounts):
    """Measured modes of a frame: sensors (dicts of the contract), frequencies [Hz] and
    shapes (n_sensors, n_modes; None for frequencies only)."""

    sensors: list
    frequencies_hz: np.ndarray
    shapes: np.ndarray | None
    source: str = "measured"
    time: object = None     # optional, as a beam test's: ISO 8601 text or a number
    label: str | None = None

    @property
    def n_sensors(self) -> int:
        return 0 if self.shapes is None else len(self.sensors)

    @property
    def n_neighbour_pairs(self) -> int:
        """Pairs of neighbours in the whiteness test of the shape residuals: sensors of one
        direction are a chain along the structure (:func:`neighbour_pairs`)."""
        return max(self.n_sensors - len({chain_key(s) for s in self.sensors}), 0)


def load_frame_measured(path, model: FrameModel) -> FrameMeasured:
    """Read frame measured modes (JSON, module docstring), each sensor checked against
    ``model``; :class:`GfeInputError` (one line) on bad input."""
    from .measured import read_json

    where = str(path)
    suffix = where.lower().rsplit(".", 1)[-1]
    if suffix in ("uff", "unv"):
        return _read_frame_uff(path, model)
    if suffix == "csv":
        return _read_frame_csv(path, model)
    if suffix != "json":
        raise GfeInputError(where, None, "frame measured data are read from .json, .csv, "
                            ".uff or .unv (README \"Plane frames\")")
    return frame_measured_from_dict(read_json(path), model, where)


def locate(model: FrameModel, x: float, y: float) -> dict | None:
    """Where a point (m) lies on the frame: ``{"node": id}`` at a named node, else
    ``{"member": id, "position": m}`` on a member (within 1e-6 of the frame's size), else
    None."""
    points = np.array(list(model.nodes.values()))
    tol = 1e-6 * max(float(np.ptp(points[:, 0])), float(np.ptp(points[:, 1])))
    for node, (nx, ny) in model.nodes.items():
        if math.hypot(x - nx, y - ny) <= tol:
            return {"node": node}
    for m in model.members:
        (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
        length = model.member_length(m)
        c, s = (x1 - x0) / length, (y1 - y0) / length
        along = (x - x0) * c + (y - y0) * s
        across = -(x - x0) * s + (y - y0) * c
        if abs(across) <= tol and -tol <= along <= length + tol:
            return {"member": m.id, "position": float(min(max(along, 0.0), length))}
    return None


def _read_frame_uff(path, model: FrameModel) -> FrameMeasured:
    """A universal file of a frame test: node coordinates (x, y) from dataset 15 or 2411,
    one dataset 55 (normal mode) per mode with the x and y components in r1 and r2.  Each
    node is placed on the frame (:func:`locate`); each of its two components that is not
    zero in every mode is a sensor in that direction."""
    from .measured import uff_modes

    where = str(path)
    modes, coords, nodes = uff_modes(path, plane=True)
    for i, m in enumerate(modes):
        if [int(n) for n in np.asarray(m["node_nums"]).astype(int)] != nodes:
            raise GfeInputError(where, f"dataset 55 #{i + 1}", "nodes differ from the first "
                                "mode")
    values = {c: np.array([np.real(np.asarray(m[c], dtype=complex)).ravel() for m in modes])
              for c in ("r1", "r2")}
    if any(v.shape != (len(modes), len(nodes)) for v in values.values()):
        raise GfeInputError(where, "dataset 55", "a mode has fewer values than nodes (a "
                            "damaged record)")
    sensors, columns = [], []
    for j, n in enumerate(nodes):
        if n not in coords:
            raise GfeInputError(where, "dataset 55", f"node {n} has no coordinates")
        place = locate(model, *coords[n])
        if place is None:
            raise GfeInputError(where, f"node {n}", f"at ({coords[n][0]:g}, {coords[n][1]:g}) "
                                f"m it lies on no member of {model.name}")
        for comp, direction in (("r1", "x"), ("r2", "y")):
            if np.any(values[comp][:, j] != 0):
                sensors.append({**place, "direction": direction})
                columns.append(values[comp][:, j])
    data = {"sensors": sensors, "modes": [
        {"frequency": float(m["freq"]), "shape": [float(c[i]) for c in columns]}
        for i, m in enumerate(modes)]}
    return frame_measured_from_dict(data, model, where)


#: the first cells of a frame CSV's header (then one frequency per mode)
CSV_HEADER = ("x", "y", "direction")


def _read_frame_csv(path, model: FrameModel) -> FrameMeasured:
    """A CSV of a frame test (module docstring): each row's point placed on the frame
    (:func:`locate`), its direction ``x``, ``y`` or degrees from x."""
    from .measured import csv_data_rows, csv_numbers, csv_stamp, read_text

    where = str(path)
    text = read_text(path, "measured")
    rows = csv_data_rows(text, where)
    if not rows or [c.strip().lower() for c in rows[0][:3]] != list(CSV_HEADER):
        raise GfeInputError(where, "header", "a frame's CSV starts with the header row "
                            "x,y,direction,<f1 Hz>,<f2 Hz>,... (README \"Plane frames\")")
    freqs, cells = csv_numbers(rows, where, 3, "x,y,direction", text_column=2)
    sensors, shapes = [], []
    for i, (x, y, raw, *values) in enumerate(cells, start=2):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise GfeInputError(where, f"row {i}", f"the point ({x:g}, {y:g}) is not finite")
        place = locate(model, x, y)
        if place is None:
            raise GfeInputError(where, f"row {i}", f"at ({x:g}, {y:g}) m it lies on no member "
                                f"of {model.name}")
        direction = raw.strip()
        if direction.lower() in ("x", "y"):
            direction = direction.lower()
        else:
            try:
                direction = float(direction)
            except ValueError:
                raise GfeInputError(where, f"row {i}.direction", "must be x, y or an angle in "
                                    f"degrees, got {raw!r}") from None
        sensors.append({**place, "direction": direction})
        shapes.append(values)
    data = {"modes": [{"frequency": f} for f in freqs], **{
        k: v for k, v in csv_stamp(text, where).items() if v is not None}}
    if sensors:
        data.update(sensors=sensors, modes=[
            {"frequency": f, "shape": [v[j] for v in shapes]} for j, f in enumerate(freqs)])
    return frame_measured_from_dict(data, model, where)


def frame_measured_from_dict(data, model: FrameModel, where="measured") -> FrameMeasured:
    if not isinstance(data, dict):
        raise GfeInputError(where, None, "must be a JSON object with \"modes\"")
    unknown = set(data) - {"sensors", "modes", "time", "label"}
    if unknown:
        raise GfeInputError(where, sorted(unknown)[0], "unknown key")
    stamp = time_and_label(data.get("time"), data.get("label"), where)
    sensors = data.get("sensors", [])
    if not isinstance(sensors, list):
        raise GfeInputError(where, "sensors", "must be a list of sensors")
    for i, s in enumerate(sensors):
        _check_sensor(s, model, where, f"sensors[{i}]")
    modes = data.get("modes")
    if not isinstance(modes, list) or not modes:
        raise GfeInputError(where, "modes", "missing or empty (a list of "
                            "{\"frequency\": Hz, \"shape\": [...]})")
    freqs, shapes = [], []
    for i, m in enumerate(modes):
        key = f"modes[{i}]"
        if not isinstance(m, dict):
            raise GfeInputError(where, key, "must be an object")
        f = m.get("frequency")
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f) \
                or f <= 0:
            raise GfeInputError(where, key + ".frequency", f"must be > 0 Hz, got {f!r}")
        freqs.append(float(f))
        shape = m.get("shape")
        if (shape is None) != (not sensors):
            raise GfeInputError(where, key + ".shape", "one value per sensor is needed"
                                if sensors else "a shape needs \"sensors\"")
        if shape is not None:
            if not isinstance(shape, list) or len(shape) != len(sensors) or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool)
                    and math.isfinite(v) for v in shape):
                raise GfeInputError(where, key + ".shape", f"must be {len(sensors)} finite "
                                    "numbers (one per sensor)")
            if not any(shape):
                raise GfeInputError(where, key + ".shape", "is zero at every sensor")
            shapes.append(shape)
    order = np.argsort(freqs, kind="stable")
    return FrameMeasured(sensors=list(sensors), frequencies_hz=np.array(freqs)[order],
                         shapes=np.array(shapes, dtype=float).T[:, order] if shapes else None,
                         source=where, **stamp)


def _check_sensor(s, model, where, key) -> None:
    if not isinstance(s, dict):
        raise GfeInputError(where, key, "must be an object")
    unknown = set(s) - {"node", "member", "position", "direction"}
    if unknown:
        raise GfeInputError(where, f"{key}.{sorted(unknown)[0]}", "unknown key")
    if ("node" in s) == ("member" in s):
        raise GfeInputError(where, key, "give either \"node\" or \"member\" and \"position\"")
    if "node" in s and s["node"] not in model.nodes:
        raise GfeInputError(where, key + ".node", f"no node {s['node']!r} in the model")
    if "member" in s:
        if s["member"] not in {m.id for m in model.members}:
            raise GfeInputError(where, key + ".member", f"no member {s['member']!r}")
        x, length = s.get("position"), model.member_length(model.member(s["member"]))
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0 <= x <= length:
            raise GfeInputError(where, key + ".position", f"must lie on the member, 0 to "
                                f"{length:g} m, got {x!r}")
    _angle(s.get("direction"), where, key + ".direction")


def _angle(direction, where, key) -> float:
    if direction == "x":
        return 0.0
    if direction == "y":
        return 90.0
    if isinstance(direction, (int, float)) and not isinstance(direction, bool) \
            and math.isfinite(direction):
        return float(direction)
    raise GfeInputError(where, key, f"must be \"x\", \"y\" or an angle in degrees, got "
                        f"{direction!r}")


#: observation matrices kept (a fit evaluates one model after another on one mesh)
_OBSERVATIONS: dict = {}
OBSERVATIONS_KEPT = 16


def observation(model: FrameModel, mesh: FrameMesh, sensors) -> sp.csr_matrix:
    """(n_sensors, n_dof): each sensor's reading of a displacement vector; built once a
    mesh (its nodes, elements and DOFs: a joint spring gives a member end its own rotation)
    and set of sensors, a copy returned."""
    return _kept_reading(_OBSERVATIONS, model, mesh, sensors)


#: readings of the places of point masses and springs (:func:`attached_reading`), kept
#: apart from the sensors' so that a fit moving a mass does not push theirs out
_ATTACHED: dict = {}


def attached_reading(model: FrameModel, mesh: FrameMesh, places) -> sp.csr_matrix:
    """:func:`observation` of the places where point masses or springs act (what
    ``frame._attached`` reads them with), kept as the sensors' readings are: every fit of
    another effect on a frame with a mass reads the mass's unchanged place again."""
    return _kept_reading(_ATTACHED, model, mesh, places)


def _kept_reading(kept: dict, model: FrameModel, mesh: FrameMesh, sensors) -> sp.csr_matrix:
    """:func:`build_observation` of ``sensors`` through ``mesh`` from ``kept`` (least
    recently used first out, at most :data:`OBSERVATIONS_KEPT`), then as the members
    read it (:func:`with_shear`, a copy)."""
    key = _reading_key(model, mesh, sensors)
    C = kept.pop(key, None)   # kept, it goes back in as the newest
    if C is None:
        C = build_observation(model, mesh, sensors)
        while kept and len(kept) >= OBSERVATIONS_KEPT:
            kept.pop(next(iter(kept)))   # the least recently used
    if OBSERVATIONS_KEPT > 0:
        kept[key] = C
    return with_shear(model, mesh, sensors, C)


def _reading_key(model: FrameModel, mesh: FrameMesh, sensors) -> tuple:
    """What a reading of ``sensors`` through ``mesh`` depends on besides the effects' values:
    the sensors, the mesh's nodes, elements and DOFs, and the members' meshes."""
    return (repr(sensors), mesh.n_dof, mesh.element_dofs.tobytes(), mesh.xy.tobytes(),
            tuple((m.id, m.elements) for m in model.members))


def with_shear(model: FrameModel, mesh: FrameMesh, sensors, C) -> sp.csr_matrix:
    """``C`` (:func:`build_observation`'s reading of ``sensors``) as Timoshenko members read
    them: plus :func:`shear_reading` under a ``shear`` effect; a copy either way."""
    return C + shear_reading(model, mesh, sensors) if has_shear(model) else C.copy()


def shear_reading(model: FrameModel, mesh: FrameMesh, sensors) -> sp.csr_matrix:
    r"""What Timoshenko members (a ``shear`` effect) add to the reading of sensors between
    their nodes (:func:`build_observation` is the Euler–Bernoulli one): the deflection is
    cubic Hermite in w with nodal slopes θ + γ, θ the section's rotation, as a beam's
    (:func:`gfe_opt.measured._shear_sensor_matrix`): γ at a node is the cubic interpolation
    along the member of its elements' constant shear strains
    :math:`γ_e = \frac{g}{1+g}\left(\frac{v_b - v_a}{L} - \frac{θ_a + θ_b}{2}\right)`."""
    from .frame import member_elements

    members = member_elements(model)
    rows, cols, vals = [], [], []
    for i, k, weights, across, strain in _shear_places(model, mesh, sensors):
        g = members[k].shear_g
        if g is None:
            continue   # an Euler–Bernoulli member among Timoshenko ones (a member_shear)
        for e, w, dofs in weights:
            rows += [i] * 6
            cols += dofs
            vals += (w * g[e] / (1.0 + g[e]) * across * strain).tolist()
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(sensors), mesh.n_dof))


#: :func:`_shear_places` kept (a fit of shear evaluates one g after another on one mesh)
_SHEAR_PLACES: dict = {}


def _shear_places(model: FrameModel, mesh: FrameMesh, sensors) -> list:
    """The geometry of :func:`shear_reading`, once a mesh and set of sensors (the shear
    parameters g alone change from one evaluation of a fit to the next): for each sensor
    between nodes, (its row, its member's index, [(element along the member, its weight,
    the element's global DOFs)], the direction's transverse part, the strain's row)."""
    from .measured import _element_to_node

    key = _reading_key(model, mesh, sensors)
    places = _SHEAR_PLACES.pop(key, None)
    if places is None:
        places = []
        index = {m.id: k for k, m in enumerate(model.members)}
        for i, s in enumerate(sensors):
            if "node" in s:
                continue   # a joint: read at the node, nothing interpolated
            k = index[s["member"]]
            member = model.members[k]
            L = model.member_length(member) / member.elements
            j = min(int(s["position"] // L), member.elements - 1)
            H = el.hermite(s["position"] / L - j)
            first = int(np.flatnonzero(mesh.element_member == k)[0])
            c, sn = mesh.cosines[first]
            a = math.radians(_angle(s["direction"], "", ""))
            across = math.cos(a) * -sn + math.sin(a) * c   # the direction's transverse part
            nodes = _element_to_node(member.elements)
            weights = (L * H[1] * nodes[j] + L * H[3] * nodes[j + 1]).tocoo()
            strain = np.array([sn / L, -c / L, -0.5, -sn / L, c / L, -0.5])
            places.append((i, k, [(e, w, mesh.element_dofs[first + e].tolist())
                                  for e, w in zip(weights.col, weights.data)],
                           across, strain))
        while _SHEAR_PLACES and len(_SHEAR_PLACES) >= OBSERVATIONS_KEPT:
            _SHEAR_PLACES.pop(next(iter(_SHEAR_PLACES)))   # the least recently used
    if OBSERVATIONS_KEPT > 0:
        _SHEAR_PLACES[key] = places
    return places


def build_observation(model: FrameModel, mesh: FrameMesh, sensors) -> sp.csr_matrix:
    """:func:`observation` built anew (not kept)."""
    rows, cols, vals = [], [], []
    member_index = {m.id: k for k, m in enumerate(model.members)}
    for i, s in enumerate(sensors):
        a = math.radians(_angle(s["direction"], "", ""))
        d = np.array([math.cos(a), math.sin(a)])
        if "node" in s:
            u, v, _ = mesh.node_dofs[s["node"]]
            rows += [i, i]
            cols += [u, v]
            vals += list(d)
            continue
        e, xi, L, T = _element_at(model, mesh, member_index[s["member"]], s["position"])
        R = T[:2, :2]
        local = np.zeros((2, 6))                     # (axial, transverse) from local DOFs
        local[0, [0, 3]] = el.linear(xi)             # axial: u at the ends
        local[1, [1, 2, 4, 5]] = el.hermite(xi) * el.beam_dof_scaling(L)  # across: v, θ
        row = d @ R.T @ local @ T                     # direction · (global displacement)
        rows += [i] * 6
        cols += mesh.element_dofs[e].tolist()
        vals += row.tolist()
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(sensors), mesh.n_dof))


def _element_at(model: FrameModel, mesh: FrameMesh, k: int, position: float):
    """(the mesh element of member ``k`` that holds ``position`` m from its start, ξ in it,
    its length, its rotation T from the frame's axes to the member's)."""
    member = model.members[k]
    L = model.member_length(member) / member.elements
    j = min(int(position // L), member.elements - 1)
    e = int(np.flatnonzero(mesh.element_member == k)[0]) + j
    return e, position / L - j, L, rotations(mesh.cosines[e:e + 1])[0]


def rotation_reading(model: FrameModel, mesh: FrameMesh, places) -> sp.csr_matrix:
    """The rotation θ (rad) at each of ``places`` ({"member", "position"}, m from the
    member's start) from the mesh's DOFs: at a member's end the joint's own θ (a body
    attached at a joint turns with the joint, a member end a ``joint_spring`` frees
    included); between nodes the slope of the member's cubic, dv/ds (rotation is the same
    angle in the member's axes and the frame's).  What a body's rotary inertia J adds to M
    is J c cᵀ (``attached_body``, ``rotary_inertia``)."""
    rows, cols, vals = [], [], []
    for i, place in enumerate(places):
        member = model.member(place["member"])
        length = model.member_length(member)
        x = float(place["position"])
        end = member.start if x <= 1e-12 * length else \
            member.end if x >= length * (1 - 1e-12) else None
        if end is not None:
            rows.append(i)
            cols.append(mesh.node_dofs[end][2])
            vals.append(1.0)
            continue
        k = next(j for j, m in enumerate(model.members) if m.id == member.id)
        e, xi, L, T = _element_at(model, mesh, k, x)
        slope = np.zeros(6)                          # dv/ds from the local DOFs
        slope[[1, 2, 4, 5]] = el.hermite_d1(xi) * el.beam_dof_scaling(L) / L
        rows += [i] * 6
        cols += mesh.element_dofs[e].tolist()
        vals += (slope @ T).tolist()
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(places), mesh.n_dof))


#: shape residuals below this (relative to the largest amplitude) are rounding: far above
#: eps times the condition of a frame's modal solve, far below any sensor's noise
ROUNDING = 1e-9


@dataclass(frozen=True)
class FrameComparison(PairSummary):
    """Pairs (as :class:`~gfe_opt.correlation.Pair`), the MAC matrix, each sensor's shape
    residual over the paired modes, the notes."""

    pairs: list
    mac_matrix: np.ndarray | None
    sensors: list
    residual: np.ndarray | None
    notes: list = field(default_factory=list)
    model_modes: object = None        # Modes of the model (all DOFs), for the figures
    scale: np.ndarray | None = None   # per pair: the factor that fits the model's shape to y

    @property
    def pairing(self) -> str:
        return "frequency" if self.mac_matrix is None else "mac"

    def failure_places(self, at_most: int = 3) -> list[tuple[dict, float]]:
        """The sensors with the largest shape residual (relative to the largest), largest
        first."""
        if self.residual is None or not np.any(self.residual > ROUNDING):
            return []
        order = np.argsort(-self.residual, kind="stable")[:at_most]
        return [(self.sensors[i], float(self.residual[i] / self.residual.max()))
                for i in order]

    def to_json(self) -> dict:
        """``compare --json`` on a frame: the beam's keys, localisation by sensor."""
        return {"pairs": [{"test_mode": p.test_mode, "model_mode": p.model_mode,
                           "test_hz": p.test_hz, "model_hz": p.model_hz,
                           "error_pct": p.error_pct, "mac": p.mac} for p in self.pairs],
                "freq_error_rms_pct": self.freq_error_rms_pct, "mac_mean": self.mac_mean,
                "localisation": None if self.residual is None else [
                    {"sensor": s, "residual": float(r)}
                    for s, r in zip(self.sensors, self.residual)],
                "pairing": self.pairing}


def compare_frame(model: FrameModel, measured: FrameMeasured,
                  mac_threshold: float | None = None) -> FrameComparison:
    """Pair measured and model modes (by MAC at the sensors, as for beams, or by frequency
    without shapes), frequency errors, and each sensor's shape residual: the rms over the
    pairs of (y − a φ)/max|y|, y the measured shape and a φ the model's at the sensors scaled
    to it by least squares."""
    from .correlation import (
        DEFAULT_MAC_THRESHOLD,
        Pair,
        mac,
        pair_by_frequency,
        pair_modes,
        plausible,
    )

    threshold = DEFAULT_MAC_THRESHOLD if mac_threshold is None else mac_threshold
    disc = FrameDiscretisation(model)
    mesh = disc.mesh
    modes = frame_modes(model, min(2 * measured.n_modes + 6, disc.free.size - 1), disc)
    f_model = modes.frequencies_hz
    if measured.shapes is None:
        idx = pair_by_frequency(measured.frequencies_hz, f_model)
        mac_matrix = None
    else:
        at = observation(model, mesh, measured.sensors) @ modes.shapes
        mac_matrix = mac(measured.shapes, at)
        idx = pair_modes(np.where(f_model > 0, mac_matrix, 0.0), threshold,
                         measured.frequencies_hz, f_model)
    if not idx:
        raise GfeSolverError(f"no test mode pairs with any model mode (MAC >= {threshold}); "
                             "check sensors, directions and units")
    pairs = [Pair(test_mode=t + 1, model_mode=m + 1, test_hz=float(measured.frequencies_hz[t]),
                  model_hz=float(f_model[m]),
                  error_pct=float(100 * (f_model[m] / measured.frequencies_hz[t] - 1)),
                  mac=None if mac_matrix is None else float(mac_matrix[t, m]))
             for t, m in idx]
    notes = []
    if mac_matrix is not None:   # a shape pair 20 times off in frequency: not one mode
        pairs, _ = plausible(pairs, measured.source, notes)
        idx = [(p.test_mode - 1, p.model_mode - 1) for p in pairs]
    unpaired = sorted(set(range(measured.n_modes)) - {t for t, _ in idx})
    if unpaired:
        notes.append(f"test mode(s) {[u + 1 for u in unpaired]} have no model mode with "
                     f"MAC >= {threshold}")
    residual = None
    if mac_matrix is not None:
        r, scale = [], []
        for t, m in idx:
            y, phi = measured.shapes[:, t], at[:, m]
            a = float(phi @ y) / float(phi @ phi)
            scale.append(a)
            r.append((y - a * phi) / np.max(np.abs(y)))
        residual = np.sqrt(np.mean(np.square(r), axis=0))
    return FrameComparison(pairs=pairs, mac_matrix=mac_matrix, sensors=measured.sensors,
                           residual=residual, notes=notes, model_modes=modes,
                           scale=None if residual is None else np.array(scale))


def sensor_order(model: FrameModel, sensors) -> np.ndarray:
    """The sensors in order along the structure: member by member (file order), from each
    member's start; a sensor at a node counts at the first member that starts or ends
    there.  Neighbours in this order are neighbours on a member (the whiteness of the
    shape residuals, as along a beam)."""
    keys = []
    for s in sensors:
        if "node" in s:
            i, m = next((i, m) for i, m in enumerate(model.members)
                        if s["node"] in (m.start, m.end))
            at = 0.0 if s["node"] == m.start else model.member_length(m)
        else:
            i = next(i for i, m in enumerate(model.members) if m.id == s["member"])
            at = s["position"]
        keys.append((i, at))
    return np.array(sorted(range(len(keys)), key=lambda k: keys[k]), dtype=int)


def chain_key(sensor: dict) -> str:
    """The chain of the whiteness test a sensor belongs to: its direction."""
    return str(sensor["direction"])


def neighbour_pairs(model: FrameModel, sensors) -> tuple[np.ndarray, np.ndarray]:
    """Neighbouring sensors for the whiteness test: the sensors of each direction in order
    along the structure (:func:`sensor_order`), each with the next of the same direction.
    An x and a y reading at one point are two components, not neighbours: model error
    correlates a component along the structure, not one component with the other."""
    order = sensor_order(model, sensors)
    a, b = [], []
    for d in dict.fromkeys(chain_key(s) for s in sensors):
        chain = [i for i in order if chain_key(sensors[i]) == d]
        a += chain[:-1]
        b += chain[1:]
    return np.array(a, dtype=int), np.array(b, dtype=int)


def sensor_places(model: FrameModel, sensors) -> tuple[np.ndarray, np.ndarray]:
    """Each sensor's point (x, y) and unit direction, in the frame's axes."""
    points, directions = [], []
    for s in sensors:
        if "node" in s:
            points.append(model.nodes[s["node"]])
        else:
            m = model.member(s["member"])
            (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
            t = s["position"] / model.member_length(m)
            points.append((x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
        a = math.radians(_angle(s["direction"], "", ""))
        directions.append((math.cos(a), math.sin(a)))
    return np.array(points, dtype=float), np.array(directions)


def frame_figures(result: FrameComparison, model: FrameModel, measured: FrameMeasured) -> dict:
    """``compare --plot`` on a frame: the MAC matrix, paired frequencies, each paired mode
    drawn on the frame (the model's deformed shape, the measured displacements as arrows)
    and the frame with every sensor coloured by its shape residual."""
    from . import plots

    pairs = [(p.test_mode - 1, p.model_mode - 1) for p in result.pairs]
    figs = {"frequencies.png": plots.paired_frequencies(result.pairs)}
    if result.mac_matrix is None:
        return figs
    mesh = frame_mesh(model)
    points, directions = sensor_places(model, measured.sensors)
    members = [mesh.xy[nodes] for nodes in mesh.member_nodes]
    shapes = []
    for (t, m), a in zip(pairs, result.scale):
        phi = result.model_modes.shapes[:, m] * a
        n = mesh.xy.shape[0]
        shapes.append((phi[0:3 * n:3], phi[1:3 * n:3], measured.shapes[:, t]))
    titles = [f"mode {p.test_mode}: {p.test_hz:.4g} Hz test, {p.model_hz:.4g} Hz model, "
              f"MAC {p.mac:.3f}" for p in result.pairs]
    figs["mac.png"] = plots.mac_matrix(result.mac_matrix, pairs)
    figs["frame_modes.png"] = plots.frame_modes(members, mesh.member_nodes, mesh.xy, shapes,
                                                points, directions, titles)
    figs["frame_localisation.png"] = plots.frame_localisation(
        members, points, result.residual,
        [sensor_label(s) for s, _ in result.failure_places()],
        [sensor_label(s) for s in measured.sensors])
    return figs


def frame_diagnosis_figures(diagnosis, model: FrameModel, title: str, found) -> dict:
    """``diagnose --plot`` on a frame: the effects found (``found``, as
    :func:`gfe_opt.report.findings` gives them) drawn on the frame at their places with
    their fitted values, and the sensors where the model as it stands fails most
    (``diagnosis.localisation``); titled with the verdict (``title``)."""
    from . import plots

    mesh = frame_mesh(model)
    members = [mesh.xy[nodes] for nodes in mesh.member_nodes]
    marks = [_mark(model, kind.name, params) for kind, _, params, _, _ in found]
    failing = []
    for sensor, _ in diagnosis.localisation or []:
        point, _ = sensor_places(model, [sensor])
        failing.append((tuple(point[0]), sensor_label(sensor)))
    # what the data do not decide about the finding (the diagnosis's caveats, in their own
    # words) and where else its effect fits as well (their alternatives, drawn hollow)
    caveats = diagnosis.caveats
    elsewhere = [_mark(model, e.name, e.parameters) for e in diagnosis.drawn_alternatives
                 if "member" in e.parameters or "node" in e.parameters]
    deciding = []
    for sensor in diagnosis.deciding_sensors:
        point, _ = sensor_places(model, [sensor])
        deciding.append((tuple(point[0]), sensor_label(sensor)))
    return {"frame_diagnosis.png": plots.frame_findings(members, marks, failing, title,
                                                        [str(c) for c in caveats],
                                                        elsewhere, deciding)}


def effect_place(model: FrameModel, effect) -> str:
    """Where an effect sits on a frame, in words: ``node C`` (an effect at a named node, or
    along a member within 2 % of its length of one: a mass at either member's end of a
    joint is one place), ``beam at 0.132 m``, or the member (an axial stiffness).  A joint
    spring's place is its joint and member end."""
    p = effect.parameters
    if effect.name == "joint_spring":
        return f"node {p['node']} ({p['member']}'s end)"
    if "length" in p and "member" in p:   # a zone: its extent along its member
        a, b = p["position"] - p["length"] / 2, p["position"] + p["length"] / 2
        return f"{p['member']} from {a:.3g} to {b:.3g} m"
    if "position" in p and "member" in p:
        m = model.member(p["member"])
        length = model.member_length(m)
        along = f" in {p['direction']}" if "direction" in p else ""   # a point spring's
        for node, at in ((m.start, 0.0), (m.end, length)):
            if abs(p["position"] - at) <= 0.02 * length:
                return f"node {node}{along}"
        return f"{m.id} at {p['position']:.3g} m{along}"
    if "node" in p:
        return f"node {p['node']}" + (f" in {p['direction']}" if "direction" in p else "")
    return str(p.get("member", "the frame"))


def mirror_members(model: FrameModel) -> dict | None:
    """{member id: (its image's id, whether the image runs the other way)} when the frame
    (nodes, supports, members' sections, materials and meshes; its effects not looked at)
    is its own mirror image about the vertical line through the middle of its nodes'
    x-range, else None.  A portal's beam is its own image, run the other way; its columns
    are each other's.  Nodes match within 10⁻⁶ of the frame's size."""
    xs = [x for x, _ in model.nodes.values()]
    ys = [y for _, y in model.nodes.values()]
    middle = 0.5 * (min(xs) + max(xs))
    tol = 1e-6 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-300)
    image = {}
    for node, (x, y) in model.nodes.items():
        match = [n for n, (u, v) in model.nodes.items()
                 if abs(u - (2 * middle - x)) <= tol and abs(v - y) <= tol]
        if len(match) != 1:
            return None
        image[node] = match[0]
    supports = dict(model.supports)
    if any(supports.get(image[n]) != t for n, t in supports.items()):
        return None
    ends = {(m.start, m.end): m for m in model.members}
    out = {}
    for m in model.members:
        forward = ends.get((image[m.start], image[m.end]))
        backward = ends.get((image[m.end], image[m.start]))
        other = forward or backward
        if other is None or (other.elements, other.E, other.rho, other.nu, other.area,
                             other.inertia, other.depth) != (
                m.elements, m.E, m.rho, m.nu, m.area, m.inertia, m.depth):
            return None
        out[m.id] = (other.id, forward is None)
    return out


def _mark(model: FrameModel, name: str, params: dict):
    """(name, (x, y), label, member polyline or None) of an effect found on a frame: a crack
    or a mass at its place on its member, a joint spring just off its joint along its
    member (which member end turns), a support effect at its node, an axial stiffness or load
    along its member, a material along every member, a section loss over its zone."""
    def along(member_id, t):
        m = model.member(member_id)
        (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
        return (x0 + t * (x1 - x0), y0 + t * (y1 - y0)), m

    from .effects import effect_type

    kind = effect_type(name)

    def unit(key):
        u = kind.parameter(key).unit
        return f" {u}" if u not in ("", "-") else ""

    values = ", ".join(f"{k} {v:.3g}{unit(k)}" for k, v in params.items()
                       if k != "position" and isinstance(v, (int, float)))
    if isinstance(params.get("ratio"), (list, tuple)):   # a profile: EI × ratio at its knots
        what = "ρA × " if name == "mass_profile" else "EI × "
        values = what + ", ".join(f"{r:.3g}" for r in params["ratio"]) + " at " + \
            ", ".join(f"{x:.3g}" for x in params["x"]) + " m"
    line = None
    if "length" in params:   # a zone: drawn over its extent on its member
        m = model.member(params["member"])
        span = model.member_length(m)
        ends = [along(m.id, (params["position"] + side * params["length"] / 2) / span)[0]
                for side in (-1, 1)]
        point, line = along(m.id, params["position"] / span)[0], np.array(ends, dtype=float)
        label = f"{name} on {m.id} at {params['position']:.3g} m: {values}"
    elif "position" in params:
        m = model.member(params["member"])
        point, _ = along(m.id, params["position"] / model.member_length(m))
        label = f"{name} on {m.id} at {params['position']:.3g} m" + (
            f" in {params['direction']}" if "direction" in params else "") + f": {values}"
    elif name == "joint_spring":
        m = model.member(params["member"])
        t = 0.06 if params["node"] == m.start else 0.94
        point, _ = along(m.id, t)
        label = f"{name} at {params['node']} ({m.id}): {values}"
    elif "node" in params:
        point = model.nodes[params["node"]]
        label = f"{name} at {params['node']}" + (f" in {params['direction']}"
                                                   if "direction" in params else "") + \
            f": {values}"
    elif "member" in params:
        point, m = along(params["member"], 0.5)
        line = np.array([model.nodes[m.start], model.nodes[m.end]], dtype=float)
        label = f"{name} of {m.id}: {values}"
    else:   # the whole frame (a material): every member drawn, numbered on the first
        point, _ = along(model.members[0].id, 0.5)
        line = np.array([p for m in model.members
                         for p in (model.nodes[m.start], model.nodes[m.end], (np.nan, np.nan))],
                        dtype=float)   # NaN: one stroke a member
        label = f"{name} of every member: {values}" + (
            f" (κGA of {model.members[0].id}; the others' by their GA)"
            if name == "shear" else "")
    return name, tuple(point), label, line


def sensor_label(sensor: dict) -> str:
    """``node B, x`` or ``beam at 0.25 m, y``."""
    where = (f"node {sensor['node']}" if "node" in sensor
             else f"{sensor['member']} at {sensor['position']:g} m")
    d = sensor["direction"]
    return f"{where}, {d if isinstance(d, str) else f'{d:g}°'}"

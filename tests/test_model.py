"""Model files: the contract form loads; bad input is named in one line."""

import textwrap

import pytest

from gfe_opt.errors import GfeInputError
from gfe_opt.model import load_model

CONTRACT = """\
name = "ss-steel-beam"
kind = "beam"            # "beam" (transverse w, rotation) or "bar" (axial u)
length = 0.575           # m
elements = 46
[material]
E = 206e9                # Pa
rho = 7800               # kg/m^3
nu = 0.3
[section]
shape = "rectangle"      # or give A (m^2) and I (m^4) directly
b = 0.009525             # m, breadth
h = 0.03175              # m, depth
[supports]
left = "pinned"          # pinned | clamped | free | sliding (bar: fixed | free)
right = "pinned"
"""


def _write(tmp_path, text):
    p = tmp_path / "m.toml"
    p.write_text(text)
    return p


def test_contract_form_loads(tmp_path):
    m = load_model(_write(tmp_path, CONTRACT))
    assert (m.name, m.kind, m.elements, m.supports) == ("ss-steel-beam", "beam", 46,
                                                        ("pinned", "pinned"))
    assert m.area == pytest.approx(0.009525 * 0.03175)
    assert m.inertia == pytest.approx(0.009525 * 0.03175**3 / 12)


def test_effects_tables_load(tmp_path):
    text = CONTRACT + textwrap.dedent("""
        [[effects]]
        effect = "crack"
        position = 0.19
        depth_ratio = 0.5
        [[effects]]
        effect = "support_spring"
        stiffness = 1e3
        side = "both"
        """)
    m = load_model(_write(tmp_path, text))
    assert [e.name for e in m.effects] == ["crack", "support_spring"]
    assert m.effects[0].parameters == {"position": 0.19, "depth_ratio": 0.5}


@pytest.mark.parametrize("old,new,match", [
    ("elements = 46", "elements = 0", "elements: must be an integer >= 1"),
    ("E = 206e9", "E = -206e9", "material.E: must be > 0"),
    ("E = 206e9", "E = nan", "material.E: must be finite"),
    ("rho = 7800", "rhoo = 7800", "material.rhoo: unknown key \\(did you mean 'rho'\\?\\)"),
    ('left = "pinned"', 'left = "hinged"', "supports.left: unknown value 'hinged'"),
    ('kind = "beam"', 'kind = "plate"', "kind: unknown value 'plate'"),
    ("length = 0.575", "", "length: missing"),
    ('shape = "rectangle"', 'shape = "circle"', "section.shape: unknown shape"),
    ("[supports]", "[supports", "not valid TOML"),
])
def test_bad_model_files(tmp_path, old, new, match):
    path = _write(tmp_path, CONTRACT.replace(old, new))
    with pytest.raises(GfeInputError, match=match) as info:
        load_model(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("effect,match", [
    ('effect = "rust"', "unknown effect 'rust'"),
    ('effect = "crack"\nposition = 0.9\ndepth_ratio = 0.5', "outside the structure"),
    ('effect = "crack"\nposition = 0.2\ndepth_ratio = 1.5', "depth_ratio: must lie betw"),
    ('effect = "crack"\nposition = 0.2', "depth_ratio: missing"),
    ('effect = "support_spring"\nstiffness = 1.0\nside = "top"', "side: must be one of"),
])
def test_bad_effects(tmp_path, effect, match):
    with pytest.raises(GfeInputError, match=match):
        load_model(_write(tmp_path, CONTRACT + "[[effects]]\n" + effect + "\n"))


def test_missing_file_is_input_error(tmp_path):
    with pytest.raises(GfeInputError, match="nope.toml: no such file"):
        load_model(tmp_path / "nope.toml")
    assert issubclass(GfeInputError, ValueError)

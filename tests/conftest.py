"""Shared builders for test models (plain dicts in the model-file form)."""

import copy

import pytest
from hypothesis import settings

from gfe_opt.model import model_from_dict

# hypothesis profiles: "ci" (default, 600 examples per fuzz test, about 40 s in all)
# and "long" (python scripts/fuzz.py, or --hypothesis-profile long); tests that set their own
# max_examples keep it
settings.register_profile("ci", max_examples=600, deadline=None)
settings.register_profile("long", max_examples=30000, deadline=None)
settings.load_profile("ci")

STEEL_BEAM = {
    "name": "ss-steel-beam", "kind": "beam", "length": 0.575, "elements": 46,
    "material": {"E": 206e9, "rho": 7800.0, "nu": 0.3},
    "section": {"shape": "rectangle", "b": 0.009525, "h": 0.03175},
    "supports": {"left": "pinned", "right": "pinned"},
}
STEEL_BAR = {
    "name": "bar", "kind": "bar", "length": 2.0, "elements": 20,
    "material": {"E": 70e9, "rho": 2700.0},
    "section": {"A": 1e-4},
    "supports": {"left": "fixed", "right": "free"},
}


def make_model(base=STEEL_BEAM, **changes):
    data = copy.deepcopy(base)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key].update(value)
        else:
            data[key] = value
    return model_from_dict(data, "test-model")


@pytest.fixture
def beam():
    return make_model()

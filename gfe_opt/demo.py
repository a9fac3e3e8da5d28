"""``gfe-opt demo``: the story on a synthetic cracked beam, told step by step."""

from __future__ import annotations

import shutil
from pathlib import Path

from .cli import format_comparison
from .correlation import compare
from .errors import GfeInputError
from .measured import save_measured
from .model import Effect, load_model
from .problems import problem_file
from .synthetic import interior_sensors, synthetic_measurement

#: The hidden truth of the demo: a crack the starting model does not have.
DEMO_CRACK = {"position": 0.19, "depth_ratio": 0.5}


def run_demo(out: Path, force: bool = False) -> int:
    model_path, measured_path = out / "model.toml", out / "measured.json"
    existing = [p for p in (model_path, measured_path) if p.exists()]
    if existing and not force:
        raise GfeInputError(str(existing[0]), None,
                            "exists already; pass --force to overwrite the demo's files")
    out.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(problem_file("ss-steel-beam.toml"), model_path)
    model = load_model(model_path)
    print("gfe-opt demo: a model that disagrees with a modal test\n")
    print(f"1. The model ({model_path}): a simply supported steel beam, "
          f"{1000 * model.length:.0f} mm long, {1000 * model.depth:.2f} x "
          f"{1000 * model.breadth:.3f} mm, {model.elements} Euler-Bernoulli elements.")
    truth = model.with_effects([Effect("crack", DEMO_CRACK)])
    sensors = interior_sensors(model.length, 45)
    measured = synthetic_measurement(truth, 5, sensors, shape_noise=0.003, freq_noise=0.0005,
                                     seed=2002)
    save_measured(measured, measured_path)
    print(f"2. The test ({measured_path}): 5 modes at 45 accelerometers, simulated with an "
          "independent fine model\n   of the real beam, which has a crack the model lacks "
          "(0.3 % shape noise, 0.05 % frequency noise).")
    print("3. Compare the model with the test and see where it fails:\n")
    result = compare(model, measured)
    print("   " + format_comparison(result, model.length).replace("\n", "\n   "))
    places = result.failure_places()
    if places:
        print(f"\n   The hidden crack is at x = {DEMO_CRACK['position']} m; the residual force "
              f"points to x = {places[0][0]:.3f} m.")
    print(f"\nReproduce step 3 with:\n  gfe-opt compare {model_path} {measured_path}")
    return 0

"""Issue 17 item 2: the full-scale KVLCC2 keeps model-scale wake and rudder-flow factors; until they
are scaled the model file and the README must say plainly that its full-scale maneuvers are not a
prediction. The ITTC-1978 wake scaling the note quotes is checked here."""

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _ittc78_wake(w_m, t, k, cf_m, cf_s, dcf):
    """ITTC 7.5-02-03-01.4 (ITTC-1978 method): w_S = (t + 0.04) + (w_M − t − 0.04)((1+k)C_FS + ΔC_F)/((1+k)C_FM)."""
    return (t + 0.04) + (w_m - t - 0.04) * ((1 + k) * cf_s + dcf) / ((1 + k) * cf_m)


def test_quoted_full_scale_wake():
    re_m = 1.047 * 7.0 / 1.14e-6  # KVLCC2 L7 at its 1.047 m/s (SIMMAN 2008), fresh water 15 °C
    cf_m = 0.075 / (__import__("math").log10(re_m) - 2) ** 2
    assert abs(cf_m - 0.00325) < 2e-5
    w_s = _ittc78_wake(0.40, 0.22, 0.2, cf_m, 0.001395, 0.00015)
    assert 0.32 < w_s < 0.34


def test_model_file_and_readme_say_full_scale_maneuvers_are_not_a_prediction():
    text = (ROOT / "models" / "kvlcc2" / "ship.toml").read_text()
    ship = tomllib.loads(text)
    if ship["propeller"][0]["w_P0"] == 0.40:  # still the model-scale wake
        assert "FULL-SCALE MANEUVERS ARE NOT A PREDICTION" in text
        assert "full-scale KVLCC2 maneuvers are not a prediction" in (ROOT / "README.md").read_text()

"""Reliability: every bad input ends in a one-line VtrialsError naming file and field, nothing is
written; names are safe; the Python API raises only VtrialsError subclasses for bad input.

Property-based (hypothesis): scenario and model files are generated from the shipped ones by one
mutation each that makes them wrong by construction — a value of the wrong type, a non-finite or
huge number, an unknown key, a missing required key, an unsafe name, a bad instrument setting, a
table where a value belongs and the reverse. Beside them, a corpus of named cases from issue 12.
"""

from __future__ import annotations

import functools
import json
import math
import re
import shutil
import tempfile
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import vtrials
import vtrials.scenario as scenario_mod
from vtrials.cli import main
from vtrials.errors import InputError, VtrialsError
from vtrials.physics.vessel import MODELS_DIR, load_vessel
from vtrials.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
FUZZ = settings(max_examples=1400, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


# ------------------------------------------------------------------------------------ TOML writing
def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)


def to_toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # JSON escapes are TOML basic-string escapes
    if isinstance(v, list):
        return "[" + ", ".join(to_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {to_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(doc: dict) -> str:
    """A document as top-level keys with inline values (valid TOML 1.0; tomllib reads it back)."""
    return "\n".join(f"{_key(k)} = {to_toml_value(v)}" for k, v in doc.items()) + "\n"


def test_toml_writer_round_trips():
    for f in sorted(SCENARIOS.glob("*.toml")):
        doc = tomllib.loads(f.read_text())
        assert tomllib.loads(to_toml(doc)) == doc


# ------------------------------------------------------------------------------------ base documents
def _base(name: str, extra: dict | None = None) -> dict:
    doc = tomllib.loads((SCENARIOS / name).read_text())
    doc.update(extra or {})
    return doc


_SITE = {"latitude_deg": 38.0, "transponder_side": -1.0, "range_center_north_m": 100.0,
         "transponders": [[-12000.0, -9000.0], [-12000.0, 9000.0]], "hydrophones": [[-600.0, -800.0], [-600.0, 800.0]]}
_INSTR = [{"name": "gyro2", "spec": "gyrocompass", "site": "gyro",
           "set": {"noise": 0.05, "rate_hz": 2.0, "dropout_p": 0.01, "range": [-400.0, 400.0],
                   "bias": {"mean": 0.0, "sd": 0.1}, "latency_s": 0.1}}]
BASES = {
    "maneuvers": _base("patrol51_maneuvers.toml", {"site": _SITE, "instrument": _INSTR}),
    "kvlcc2": _base("kvlcc2_l7_turning.toml"),
    "log_calibration": _base("patrol51_log_calibration.toml", {"site": _SITE}),
    "standardization": _base("patrol51_standardization.toml"),
}
for _name, _doc in BASES.items():  # every base is valid, so each mutation alone makes it wrong
    _p = Path(tempfile.mkdtemp()) / "s.toml"
    _p.write_text(to_toml(_doc))
    load_scenario(_p)


def _paths(x, prefix=()):
    """Every path to a value in a document (keys and list indices), parents before children."""
    out = []
    if isinstance(x, dict):
        for k, v in x.items():
            out.append(prefix + (k,))
            out += _paths(v, prefix + (k,))
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out.append(prefix + (i,))
            out += _paths(v, prefix + (i,))
    return out


def _get(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def _set(doc, path, value):
    _get(doc, path[:-1])[path[-1]] = value


def _copy(doc):
    return json.loads(json.dumps(doc))


def _in_set(path) -> bool:
    return "set" in path


NAME_FIELDS = {"name"}
BAD_NAMES = ["../../escape", "a/b", "", ".", "..", "x" * 300, "nul\x00name", "a\\b", "-lead", ".hidden",
             "with space", "tab\tname", "new\nline", "é", "a" * 65]
BAD_SETTINGS = {
    "noise": [-0.1, "loud", math.nan, math.inf, [0.1], {"sd": 1.0}, True],
    "rate_hz": [0.0, -1.0, "fast", math.nan, 1e9],
    "dropout_p": [1.0, 2.0, -0.1, "often", math.nan],
    "range": [[1.0, 0.0], [1.0], "wide", [0.0, math.inf], [5.0, 5.0], {"lo": 0}],
    "bias": [{"mean": 0.0, "sd": -1.0}, {"mean": math.nan, "sd": 0.1}, {"men": 0.0}, "none", [1.0]],
    "latency_s": [-1.0, "late", math.inf, 1e9],
    "resolution": [-0.01, "fine"],
    "misalignment_deg": [-1.0, 1000.0],
    "gauss_markov": [{"sd": 1.0, "tau_s": 0.0}, {"sd": -1.0, "tau_s": 10.0}, 3.0],
    "update_s": [[0.0, 1.0], [2.0, 1.0], "x"],
    "clock_offset_s": [-0.1, math.nan],
    "scale": [{"mean": -2.0, "sd": 0.0}, {"mean": 0.0, "sd": 5.0}],
}
WRONG_FOR = {  # values of another type than the original's
    "num": ["12", "twelve", [1.0], {"valu": 1.0}, True, [], {}],
    "str": [12, 1.5, ["x"], {"x": 1}, True, [], {}],
    "bool": [1, "yes", [True], {}],
    "list": ["x", 3.0, {"a": 1}],
    "dict": [5, "x", [1, 2], True],
}


def _wrong(v) -> list:
    """Values of another type than v; for a sourced number { value, source } (ship files), values that
    are not a number either (a bare number would be valid there: the table's source applies)."""
    if isinstance(v, dict) and "value" in v:
        return ["x", [1, 2], True, {"source": "s"}, {"value": "1", "source": "s"}]
    return WRONG_FOR[_kind(v)]


def _kind(v) -> str:
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "num"
    return type(v).__name__


@st.composite
def bad_scenario(draw, bases=tuple(BASES)):
    """(document, what was done) — one mutation that makes a valid scenario wrong."""
    base = draw(st.sampled_from(bases))
    doc = _copy(BASES[base])
    paths = _paths(doc)
    how = draw(st.sampled_from(["wrong_type", "non_finite", "huge", "unknown_key", "missing", "bad_name",
                                "bad_setting", "table_swap"]))
    if how == "bad_setting" and "instrument" not in doc:
        how = "wrong_type"
    if how == "wrong_type":
        path = draw(st.sampled_from([p for p in paths if not _in_set(p)]))
        v = _get(doc, path)
        new = draw(st.sampled_from(_wrong(v)))
        _set(doc, path, new)
    elif how in ("non_finite", "huge"):
        nums = [p for p in paths if _kind(_get(doc, p)) == "num" and not _in_set(p)]
        path = draw(st.sampled_from(nums))
        vals = [math.nan, math.inf, -math.inf] if how == "non_finite" else [1e300, -1e300]
        new = draw(st.sampled_from(vals))
        _set(doc, path, new)
    elif how == "unknown_key":
        tables = [()] + [p for p in paths if isinstance(_get(doc, p), dict)]
        path = draw(st.sampled_from(tables))
        t = _get(doc, path)
        key = draw(st.sampled_from(sorted(t) or ["x"])) + draw(st.sampled_from(["_x", "s", "2"]))
        if key in t:
            key += "_zz"
        t[key] = 1.0
        new = key
    elif how == "missing":
        req = [p for p in paths if p[-1] in ("title", "ship", "seed", "timestep_s", "kind", "name", "spec")
               and not _in_set(p) and (p[0] != "agenda" or p[-1] in ("kind", "name"))]
        path = draw(st.sampled_from(req))
        del _get(doc, path[:-1])[path[-1]]
        new = None
    elif how == "bad_name":
        names = [p for p in paths if p[-1] in NAME_FIELDS and p[0] != "scenario"]
        path = draw(st.sampled_from(names))
        new = draw(st.sampled_from(BAD_NAMES))
        _set(doc, path, new)
    elif how == "bad_setting":
        key = draw(st.sampled_from(sorted(BAD_SETTINGS)))
        new = draw(st.sampled_from(BAD_SETTINGS[key]))
        path = ("instrument", 0, "set", key)
        _set(doc, path, new)
    else:  # a table where a value belongs, a value where a table or a list of tables belongs
        path = draw(st.sampled_from([p for p in [("environment",), ("site",), ("initial",), ("maneuver",),
                                                 ("agenda",), ("instrument",), ("scenario",)] if p[0] in doc]
                                    + [("environment", "current"), ("environment", "wind")]))
        new = draw(st.sampled_from([5, "x", [1, 2], True, 1.5, [{"a": 1}] if path != ("maneuver",) else {"a": 1}]))
        if len(path) == 2 and "environment" not in doc:
            doc["environment"] = {}
        _set(doc, path, new)
    return doc, f"{base}: {how} at {'.'.join(map(str, path))} = {new!r}"[:300]


@functools.lru_cache(maxsize=None)
def _builtin_vessel(name, file_for_errors=None, field_for_errors="ship"):
    return load_vessel(name, file_for_errors=file_for_errors, field_for_errors=field_for_errors)


def _vessel(name, file_for_errors=None, field_for_errors="ship"):
    """load_vessel, cached for the built-in models only (a user's model folder is read every time)."""
    if "/" in str(name):
        return load_vessel(name, file_for_errors=file_for_errors, field_for_errors=field_for_errors)
    return _builtin_vessel(name, file_for_errors, field_for_errors)


@pytest.fixture(scope="module")
def work():
    d = Path(tempfile.mkdtemp(prefix="vtrials_reliab_"))
    yield d
    shutil.rmtree(d, ignore_errors=True)


def _one_line_input_error(exc: BaseException, path: Path):
    assert isinstance(exc, VtrialsError), f"{type(exc).__name__}: {exc}"
    msg = str(exc)
    assert msg and "\n" not in msg and len(msg) < 1200, msg
    if isinstance(exc, InputError):
        assert exc.file and exc.problem
    return msg


@FUZZ
@given(case=bad_scenario())
def test_generated_bad_scenarios_raise_vtrials_error(case, work, monkeypatch_module):
    doc, what = case
    p = work / "s.toml"
    p.write_text(to_toml(doc))
    with pytest.raises(Exception) as e:
        load_scenario(p)
    msg = _one_line_input_error(e.value, p)
    assert str(p) in msg or "--" in msg, (what, msg)


@pytest.fixture(scope="module")
def monkeypatch_module():
    """The vessels of the shipped models are loaded once (the mutations do not touch them)."""
    mp = pytest.MonkeyPatch()
    mp.setattr(scenario_mod, "load_vessel", _vessel)
    yield mp
    mp.undo()


@settings(max_examples=400, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=bad_scenario(bases=("maneuvers", "log_calibration")))
def test_generated_bad_scenarios_cli_exit_2_one_line_nothing_written(case, work, monkeypatch_module, capsys):
    doc, what = case
    p = work / "c.toml"
    p.write_text(to_toml(doc))
    out = work / "out_never"
    code = main(["run", str(p), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2, (what, err)
    assert len(err.strip().splitlines()) == 1 and err.startswith("vtrials: error: "), (what, err)
    assert "Traceback" not in err
    assert not out.exists()
    assert not (work / "MUJOCO_LOG.TXT").exists() and not Path("MUJOCO_LOG.TXT").exists()


# ------------------------------------------------------------------------------------ model files
MODEL = "patrol51"
_SHIP = tomllib.loads((MODELS_DIR / MODEL / "ship.toml").read_text())
_SUITE = tomllib.loads((MODELS_DIR / MODEL / "instruments.toml").read_text())


@st.composite
def bad_model(draw):
    which = draw(st.sampled_from(["ship", "instruments"]))
    doc = _copy(_SHIP if which == "ship" else _SUITE)
    paths = [p for p in _paths(doc) if p[-1] not in ("note",) and "note" not in p]
    how = draw(st.sampled_from(["wrong_type", "non_finite", "unknown_key"] + (["bad_setting", "bad_name"]
                                                                            if which == "instruments" else [])))
    if how == "wrong_type":
        path = draw(st.sampled_from([p for p in paths if not _in_set(p)]))
        new = draw(st.sampled_from(_wrong(_get(doc, path))))
        _set(doc, path, new)
    elif how == "non_finite":
        path = draw(st.sampled_from([p for p in paths if _kind(_get(doc, p)) == "num" and not _in_set(p)]))
        new = draw(st.sampled_from([math.nan, math.inf, -math.inf]))
        _set(doc, path, new)
    elif how == "unknown_key":
        tables = [p for p in paths if isinstance(_get(doc, p), dict)]
        path = draw(st.sampled_from(tables))
        t = _get(doc, path)
        if path[-1] == "set" or (len(path) >= 2 and path[-2] == "set"):
            key = "noise_typo"
        else:
            key = (sorted(t)[0] if t else "x") + "_typo"
        t[key] = 1.0
        new = key
    elif how == "bad_name":
        path = ("instrument", draw(st.integers(0, len(doc["instrument"]) - 1)), "name")
        new = draw(st.sampled_from([n for n in BAD_NAMES if n]))
        _set(doc, path, new)
    else:
        i = draw(st.integers(0, len(doc["instrument"]) - 1))
        key = draw(st.sampled_from(sorted(BAD_SETTINGS)))
        new = draw(st.sampled_from(BAD_SETTINGS[key]))
        doc["instrument"][i].setdefault("set", {})[key] = new
        path = ("instrument", i, "set", key)
    return which, doc, f"{which}: {how} at {'.'.join(map(str, path))} = {new!r}"[:300]


@pytest.fixture(scope="module")
def model_copy(work):
    d = work / "models" / MODEL
    shutil.copytree(MODELS_DIR / MODEL, d)
    scen = work / "models" / "uses_copy.toml"
    doc = _copy(BASES["maneuvers"])
    doc["scenario"]["ship"] = f"./{MODEL}"
    scen.write_text(to_toml(doc))
    load_scenario(scen)  # the copy itself is valid
    return d, scen


@settings(max_examples=500, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=bad_model())
def test_generated_bad_model_files_raise_vtrials_error(case, model_copy):
    which, doc, what = case
    d, scen = model_copy
    target = d / ("ship.toml" if which == "ship" else "instruments.toml")
    original = (MODELS_DIR / MODEL / target.name).read_text()
    target.write_text(to_toml(doc))
    try:
        with pytest.raises(Exception) as e:
            load_scenario(scen)
    finally:
        target.write_text(original)
    msg = _one_line_input_error(e.value, scen)
    assert str(target) in msg, (what, msg)


# ------------------------------------------------------------------------------------ named cases
def _mut(base: str, edit) -> dict:
    doc = _copy(BASES[base])
    edit(doc)
    return doc


NAMED = {
    "environment = 5": (_mut("maneuvers", lambda d: d.update(environment=5)), "environment", "expected a table"),
    "site = [1, 2]": (_mut("maneuvers", lambda d: d.update(site=[1, 2])), "site", "expected a table"),
    "kind = ['turn']": (_mut("maneuvers", lambda d: d["maneuver"][0].update(kind=["turn"])), "maneuver[0].kind",
                        "expected a string"),
    "kind missing": (_mut("maneuvers", lambda d: d["maneuver"][0].pop("kind")), "maneuver[0].kind",
                     "missing field"),
    "kind misspelt": (_mut("maneuvers", lambda d: d["maneuver"][0].update(kind="turning_circel")),
                      "maneuver[0].kind", "did you mean 'turning_circle'"),
    "trial kind = {x = 1}": (_mut("log_calibration", lambda d: d["agenda"]["trial"][0].update(kind={"x": 1})),
                             "agenda.trial[0].kind", "expected a string"),
    "trial kind misspelt": (_mut("log_calibration", lambda d: d["agenda"]["trial"][0].update(kind="log_calibraton")),
                            "agenda.trial[0].kind", "did you mean 'log_calibration'"),
    "initial order misspelt": (_mut("maneuvers", lambda d: d["initial"].update(engine_order="standrd")),
                               "initial.engine_order", "did you mean 'standard'"),
    "ship misspelt": (_mut("maneuvers", lambda d: d["scenario"].update(ship="patrol5l")), "scenario.ship",
                      "did you mean 'patrol51'"),
    "noise negative": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(noise=-1.0)),
                       "instrument[0].set.noise", "out of range"),
    "noise string": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(noise="high")),
                     "instrument[0].set.noise", "expected a number"),
    "noise NaN": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(noise=math.nan)),
                  "instrument[0].set.noise", "finite"),
    "rate zero": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(rate_hz=0.0)),
                  "instrument[0].set.rate_hz", "out of range"),
    "dropout 2": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(dropout_p=2.0)),
                  "instrument[0].set.dropout_p", "out of range"),
    "range reversed": (_mut("maneuvers", lambda d: d["instrument"][0]["set"].update(range=[10.0, -10.0])),
                       "instrument[0].set.range", "low < high"),
    "range centre far": (_mut("maneuvers", lambda d: d["site"].update(range_center_north_m=1e12)),
                         "site.range_center_north_m", "out of range"),
    "current reference far": (_mut("maneuvers", lambda d: d["environment"]["current"].update(
        reference_east_m=1e9, gradient_kn_per_nmi=0.5)), "environment.current.reference_east_m", "out of range"),
    "gradient reference too far": (_mut("maneuvers", lambda d: d["environment"]["current"].update(
        reference_east_m=90000.0, gradient_kn_per_nmi=0.5)), "environment.current.reference_north_m", "kn at the range"),
    "coincident transponders": (_mut("maneuvers", lambda d: d["site"].update(transponders=[[0.0, 0.0], [0.0, 0.0]])),
                                "site.transponders[1]", "coincides"),
}
for _n in BAD_NAMES:
    NAMED[f"maneuver name {_n[:12]!r}"] = (_mut("maneuvers", lambda d, n=_n: d["maneuver"][0].update(name=n)),
                                           "maneuver[0].name", "letters, digits")
    NAMED[f"trial name {_n[:12]!r}"] = (_mut("log_calibration", lambda d, n=_n: d["agenda"]["trial"][0].update(name=n)),
                                        "agenda.trial[0].name", "letters, digits")


@pytest.mark.parametrize("case", sorted(NAMED))
def test_named_bad_inputs(case, tmp_path, capsys):
    doc, field, fragment = NAMED[case]
    p = tmp_path / "s.toml"
    p.write_text(to_toml(doc))
    out = tmp_path / "out"
    code = main(["run", str(p), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(p) in lines[0] and field in lines[0] and fragment in lines[0], lines[0]
    assert not out.exists() and not any(tmp_path.glob(".out*"))
    assert not any(tmp_path.parent.glob("escape*"))


def test_model_folder_in_working_directory_does_not_replace_builtin(tmp_path, monkeypatch):
    fake = tmp_path / "patrol51"
    shutil.copytree(MODELS_DIR / "patrol51", fake)
    (fake / "ship.toml").write_text((fake / "ship.toml").read_text().replace("length = 51.5", "length = 40.0"))
    monkeypatch.chdir(tmp_path)
    v = load_vessel("patrol51")
    assert v.folder == MODELS_DIR / "patrol51" and v.particulars.length == 51.5
    assert load_vessel("./patrol51").particulars.length == 40.0  # the user's copy, when given by its path


def test_unknown_builtin_hint_and_path():
    with pytest.raises(InputError, match=r"did you mean 'kvlcc2_l7'.*\./kvlcc2_l8"):
        load_vessel("kvlcc2_l8")
    with pytest.raises(InputError, match="no model at"):
        load_vessel("./no/such/folder")


@pytest.mark.parametrize("kwargs, field", [({"nthread": 0}, "nthread"), ({"nthread": -2}, "nthread"),
                                           ({"nthread": 1.5}, "nthread")])
def test_api_rejects_bad_nthread_before_running(kwargs, field, tmp_path):
    with pytest.raises(InputError) as e:
        vtrials.run(SCENARIOS / "kvlcc2_l7_turning.toml", tmp_path / "o", **kwargs)
    assert e.value.field == field
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("arg", [5, None, b"x", 3.5])
def test_api_bad_path_types_are_input_errors(arg):
    with pytest.raises(InputError):
        load_scenario(arg)


def test_out_checked_before_simulating(tmp_path, capsys):
    f = tmp_path / "a_file"
    f.write_text("x")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        for out, frag in ((f, "not a directory"), (f / "sub", "is not a directory"),
                          (ro / "sub", "permission denied")):
            code = main(["run", str(SCENARIOS / "kvlcc2_l7_turning.toml"), "--out", str(out), "--quiet"])
            err = capsys.readouterr().err
            if frag == "permission denied" and code != 2 and __import__("os").geteuid() == 0:
                continue  # root writes anywhere
            assert code == 2 and len(err.strip().splitlines()) == 1 and frag in err, err
            assert "--out" in err
        mine = tmp_path / "mine"  # the run replaces --out whole: never a directory of the user's files
        mine.mkdir()
        (mine / "thesis.tex").write_text("x")
        code = main(["run", str(SCENARIOS / "kvlcc2_l7_turning.toml"), "--out", str(mine), "--quiet"])
        err = capsys.readouterr().err
        assert code == 2 and "not a vtrials output (thesis.tex)" in err, err
        assert [x.name for x in mine.iterdir()] == ["thesis.tex"]
        code = main(["run", str(SCENARIOS / "kvlcc2_l7_turning.toml"), "--out", ".", "--quiet"])
        err = capsys.readouterr().err
        assert code == 2 and "working directory" in err, err
    finally:
        ro.chmod(0o755)
    assert f.read_text() == "x"


def test_inspect_directory_is_clean_error(tmp_path, capsys):
    code = main(["inspect", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "is a directory" in err and len(err.strip().splitlines()) == 1

"""What a campaign varies: a scenario file with a ``[campaign]`` table.

    [campaign]
    replicates = 200               # default number of replicates
    seed = 7                       # campaign seed: every replicate's seeds are spawned from it
    [campaign.vary]                # scenario fields drawn per replicate (dotted paths, [i] for lists)
    "environment.wind.speed_kn" = { uniform = [5.0, 20.0] }
    "environment.wind.direction_deg" = { uniform = [0.0, 360.0] }
    "environment.current.tidal_phase_deg" = { uniform = [0.0, 360.0] }
    "environment.current.tidal_amplitude_kn" = { normal = [0.8, 0.2], min = 0.0 }
    "initial.heading_deg" = { choice = [0.0, 90.0, 180.0, 270.0] }

Distributions: ``uniform = [lo, hi]``, ``normal = [mean, sd]`` (optionally clipped by ``min``/``max``),
``choice = [values...]``. Every replicate also gets its own ``scenario.seed`` (so every instrument
error and gust is drawn anew). Replicate i's draws come from the i-th child of
``SeedSequence(campaign seed)``: results do not depend on worker count or order.
"""

from __future__ import annotations

import copy
import dataclasses
import re

import numpy as np

from vtrials.errors import InputError
from vtrials.schema import load_toml

_PATH = re.compile(r"^[A-Za-z_][\w]*(\[\d+\])?(\.[A-Za-z_][\w]*(\[\d+\])?)*$")
_DISTS = ("uniform", "normal", "choice")


@dataclasses.dataclass(frozen=True)
class Vary:
    path: str
    kind: str
    args: tuple
    lo: float | None = None
    hi: float | None = None

    def draw(self, rng: np.random.Generator):
        if self.kind == "uniform":
            x = float(rng.uniform(self.args[0], self.args[1]))
        elif self.kind == "normal":
            x = float(rng.normal(self.args[0], self.args[1]))
        else:
            return self.args[int(rng.integers(len(self.args)))]
        if self.lo is not None:
            x = max(self.lo, x)
        if self.hi is not None:
            x = min(self.hi, x)
        return x


@dataclasses.dataclass(frozen=True)
class CampaignSpec:
    """A scenario's document (without its [campaign] table) and what varies per replicate."""

    path: str
    doc: dict
    vary: tuple[Vary, ...]
    replicates: int
    seed: int


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x)


def load_campaign(path: str) -> CampaignSpec:
    """Read a scenario with an optional [campaign] table; check every varied path and distribution."""
    doc = load_toml(path)
    camp = doc.pop("campaign", {})
    f = str(path)
    if not isinstance(camp, dict):
        raise InputError(f, "campaign", "expected a table")
    for k in camp:
        if k not in ("replicates", "seed", "vary"):
            raise InputError(f, f"campaign.{k}", "unknown field (allowed: replicates, seed, vary)")
    reps = camp.get("replicates", 100)
    seed = camp.get("seed", 0)
    if not isinstance(reps, int) or isinstance(reps, bool) or reps < 1:
        raise InputError(f, "campaign.replicates", f"{reps!r}: expected an integer ≥ 1")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise InputError(f, "campaign.seed", f"{seed!r}: expected an integer ≥ 0")
    vary = parse_vary(camp.get("vary", {}), doc, f, "campaign.vary")
    return CampaignSpec(f, doc, tuple(vary), reps, seed)


def parse_vary(table, doc: dict, f: str, where0: str) -> list[Vary]:
    """The draws of a ``{ "dotted.path" = { distribution } }`` table, each checked against ``doc``
    (errors name file ``f`` and field ``where0.<path>``)."""
    vary = []
    if not isinstance(table, dict):
        raise InputError(f, where0, "expected a table of 'dotted.path' = { distribution }")
    for key, d in table.items():
        where = f"{where0}.{key}"
        if not _PATH.match(key):
            raise InputError(f, where, "not a dotted field path (e.g. \"environment.wind.speed_kn\")")
        if not isinstance(d, dict):
            raise InputError(f, where, "expected { uniform = [lo, hi] }, { normal = [mean, sd] } or { choice = [...] }")
        kinds = [k for k in d if k in _DISTS]
        extra = [k for k in d if k not in _DISTS + ("min", "max")]
        if len(kinds) != 1 or extra:
            raise InputError(f, where, "give exactly one of uniform, normal, choice (and optionally min, max)")
        kind = kinds[0]
        args = d[kind]
        if not isinstance(args, list) or not args:
            raise InputError(f, f"{where}.{kind}", "expected a non-empty list")
        if kind in ("uniform", "normal"):
            if len(args) != 2 or not all(_num(a) for a in args):
                raise InputError(f, f"{where}.{kind}", "expected two finite numbers")
            if kind == "uniform" and not args[0] <= args[1]:
                raise InputError(f, f"{where}.{kind}", "lower bound above upper bound")
            if kind == "normal" and args[1] < 0:
                raise InputError(f, f"{where}.{kind}", "standard deviation must be ≥ 0")
        for b in ("min", "max"):
            if b in d and not _num(d[b]):
                raise InputError(f, f"{where}.{b}", "expected a finite number")
        _locate(doc, key, f, where)  # the field must exist or its table must
        vary.append(Vary(key, kind, tuple(args), d.get("min"), d.get("max")))
    return vary


def _locate(doc: dict, path: str, f: str, where: str):
    """(container, key) of a dotted path in doc; the last key may be missing (then it is added)."""
    parts = path.split(".")
    cur = doc
    for i, part in enumerate(parts):
        m = re.match(r"^(\w+)(?:\[(\d+)\])?$", part)
        name, idx = m.group(1), m.group(2)
        last = i == len(parts) - 1
        if last and idx is None:
            if not isinstance(cur, dict):
                raise InputError(f, where, f"{'.'.join(parts[:i])} is not a table")
            return cur, name
        if not isinstance(cur, dict) or name not in cur:
            raise InputError(f, where, f"the scenario has no {'.'.join(parts[:i + 1])}")
        cur = cur[name]
        if idx is not None:
            if not isinstance(cur, list) or int(idx) >= len(cur):
                raise InputError(f, where, f"{'.'.join(parts[:i + 1])} has no element {idx}")
            if last:
                return cur, int(idx)
            cur = cur[int(idx)]
    raise InputError(f, where, "empty path")


def replicate_seeds(campaign_seed: int, n: int) -> list[np.random.SeedSequence]:
    """One child SeedSequence per replicate (replicate i always gets the same one)."""
    return np.random.SeedSequence(campaign_seed).spawn(n)


def replicate_doc(spec: CampaignSpec, ss: np.random.SeedSequence) -> tuple[dict, dict]:
    """The scenario document of one replicate and what was drawn for it."""
    draw_ss, seed_ss = ss.spawn(2)
    rng = np.random.default_rng(draw_ss)
    doc = copy.deepcopy(spec.doc)
    drawn = {}
    for v in spec.vary:
        cont, key = _locate(doc, v.path, spec.path, f"campaign.vary.{v.path}")
        cont[key] = drawn[v.path] = v.draw(rng)
    seed = int(seed_ss.generate_state(1, np.uint64)[0] & np.uint64(2 ** 63 - 1))
    doc.setdefault("scenario", {})["seed"] = seed
    drawn["scenario.seed"] = seed
    return doc, drawn

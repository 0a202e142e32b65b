"""A ship's true airwake at its anemometer sites (``models/<ship>/airwake.toml``): truth, read by the
simulated anemometers (:class:`vtrials.instruments.devices.SonicAnemometer`), never by a reduction.

Per site, functions of the relative wind angle γ (the direction the air relative to the ship's mean
motion comes FROM, off the bow, + to starboard):

* speed factor K(γ) = 1 + s₀ + Σₖ s₂ₖ₋₁ cos kγ + s₂ₖ sin kγ (``speed``),
* direction offset δ(γ) = d₀ + Σₖ dₖ sin kγ (``direction_deg``): the local flow comes from γ + δ,
* flow inclination ε(γ) = e₀ + Σₖ e₂ₖ₋₁ cos kγ + e₂ₖ sin kγ (``upwash_deg``, + upward).

The local air velocity relative to the ship's mean motion in ship-carried vertical axes (x level along
the heading, y starboard, z down) is K S (−cos(γ + δ), −sin(γ + δ), −tan ε) + (0, 0, a_z) for an
undisturbed relative velocity of horizontal speed S and vertical component a_z.

``[mast] positions`` lists the deck sockets of the mobile anemometer mast (MJCF sites).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from vtrials.errors import InputError
from vtrials.schema import load_toml
from vtrials.units import DEG

FILE = "airwake.toml"


@dataclasses.dataclass(frozen=True)
class SiteAirwake:
    speed: tuple
    direction: tuple  # [rad]
    upwash: tuple  # [rad]
    source: str

    def evaluate(self, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(K, δ [rad], ε [rad]) at relative wind angles γ [rad]."""
        g = np.asarray(gamma, float)
        return (1.0 + _cos_sin(self.speed, g), _sin_only(self.direction, g), _cos_sin(self.upwash, g))

    def local(self, rel_level: np.ndarray) -> np.ndarray:
        """Air velocity relative to the ship's mean motion (N, 3) in ship-carried vertical axes →
        the local (distorted) air velocity there, same axes."""
        a = np.asarray(rel_level, float)
        gamma = np.arctan2(-a[:, 1], -a[:, 0])
        s = np.hypot(a[:, 0], a[:, 1])
        k, d, e = self.evaluate(gamma)
        g2 = gamma + d
        return np.column_stack([-k * s * np.cos(g2), -k * s * np.sin(g2), a[:, 2] - k * s * np.tan(e)])


def _cos_sin(c, g):
    out = np.full_like(g, float(c[0]))
    for i in range(1, (len(c) - 1) // 2 + 1):
        out = out + c[2 * i - 1] * np.cos(i * g) + c[2 * i] * np.sin(i * g)
    if len(c) % 2 == 0:  # a trailing cosine term without its sine
        i = len(c) // 2
        out = out + c[-1] * np.cos(i * g)
    return out


def _sin_only(c, g):
    out = np.full_like(g, float(c[0]))
    for i in range(1, len(c)):
        out = out + c[i] * np.sin(i * g)
    return out


@dataclasses.dataclass(frozen=True)
class Airwake:
    sites: dict  # site name → SiteAirwake
    mast_positions: tuple  # site names of the mobile mast's deck sockets
    path: str

    def site(self, name: str) -> SiteAirwake:
        if name not in self.sites:
            raise InputError(self.path, f"site.{name}", f"no airwake given for site {name!r} (sites with an airwake: "
                                                         f"{', '.join(sorted(self.sites))})")
        return self.sites[name]


NONE = SiteAirwake((0.0,), (0.0,), (0.0,), "no airwake")


def load_airwake(folder, vessel_sites: dict | None = None) -> Airwake | None:
    """The ship's airwake file, or None if it has none. Checks shapes, finiteness, that every site is a
    site of the ship, and that the speed factor stays in (0, 3) and |ε| < 60° all round."""
    p = Path(folder) / FILE
    if not p.is_file():
        return None
    f = str(p)
    doc = load_toml(p)
    for key in doc:
        if key not in ("site", "mast"):
            raise InputError(f, key, "unknown table (allowed: site, mast)")
    sites = {}
    tab = doc.get("site", {})
    if not isinstance(tab, dict) or not tab:
        raise InputError(f, "site", "expected [site.<name>] tables")
    g = np.linspace(0.0, 2 * math.pi, 361)
    for name, s in tab.items():
        sec = f"site.{name}"
        if not isinstance(s, dict):
            raise InputError(f, sec, "expected a table")
        for k in s:
            if k not in ("speed", "direction_deg", "upwash_deg", "source"):
                raise InputError(f, f"{sec}.{k}", "unknown key (allowed: speed, direction_deg, upwash_deg, source)")
        if not isinstance(s.get("source"), str) or not s["source"].strip():
            raise InputError(f, f"{sec}.source", "every airwake entry names its source")
        vals = {}
        for k, fac in (("speed", 1.0), ("direction_deg", DEG), ("upwash_deg", DEG)):
            v = s.get(k, [0.0])
            if not isinstance(v, list) or not v or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                          and math.isfinite(x) for x in v):
                raise InputError(f, f"{sec}.{k}", f"expected a non-empty list of finite numbers, got {v!r}"[:200])
            vals[k] = tuple(float(x) * fac for x in v)
        if vessel_sites is not None and name not in vessel_sites:
            raise InputError(f, sec, f"{name!r} is not a site of the ship")
        sa = SiteAirwake(vals["speed"], vals["direction_deg"], vals["upwash_deg"], s["source"])
        k, _, e = sa.evaluate(g)
        if not (np.all(k > 0.0) and np.all(k < 3.0)):
            raise InputError(f, f"{sec}.speed", f"speed factor {k.min():.3f}..{k.max():.3f} round the compass; "
                                                f"allowed: within (0, 3)")
        if np.any(np.abs(e) >= 60 * DEG):
            raise InputError(f, f"{sec}.upwash_deg", "flow inclination reaches 60° or more; allowed: |ε| < 60°")
        sites[name] = sa
    mast = doc.get("mast", {})
    pos = mast.get("positions", []) if isinstance(mast, dict) else None
    if not isinstance(pos, list) or not all(isinstance(x, str) for x in pos):
        raise InputError(f, "mast.positions", "expected a list of site names")
    for k, x in enumerate(pos):
        if x not in sites:
            raise InputError(f, f"mast.positions[{k}]", f"{x!r} has no [site.{x}] airwake entry")
    return Airwake(sites, tuple(pos), f)

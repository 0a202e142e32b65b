"""The trials team's observation of the sea state: what a directional wave buoy moored at the range
(or a hindcast) gives the analysis of a speed trial in waves (ITTC 7.5-04-01-01.1 §10.3: H_s, peak
period and mean direction of each wave system, for the STAWAVE correction).

Per wave system of the scenario's seaway, the team knows H_s, T_p and the direction it comes from,
each with an observation error drawn once per trial from its own seeded stream (independent of the
instruments' streams):

* H_s: 5 % (1σ) — assumption: the sampling variability of a 20–30-min buoy record (~150–200 waves:
  m₀ to about 10 %, H_s = 4√m₀ to about 5 %);
* T_p: 5 % (1σ) — assumption, of the same record's spectral peak;
* direction: 10° (1σ) — assumption: a buoy's mean direction in a spread (cos-2s, s = 10) sea.

The spectrum family is known (the buoy's spectrum shape): JONSWAP γ for a JONSWAP sea or swell, none
(Pierson–Moskowitz) for a Pierson–Moskowitz or Bretschneider sea.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.physics.environment.waves import peak_frequency

SEA_KEY = 6  # spawn-key namespace of the sea-state observation (instruments: 4, clocks: 5)
HS_REL_STD = 0.05
TP_REL_STD = 0.05
DIRECTION_STD_RAD = math.radians(10.0)


def observe_sea(waves, seed: int, stream: tuple = ()) -> list[dict]:
    """The observed wave systems (wind sea, swell) of a :class:`vtrials.physics.environment.waves.Waves`,
    SI: ``hs_m``, ``tp_s``, ``gamma`` (None: Pierson–Moskowitz), ``from_rad``, ``hs_rel_std``,
    ``tp_rel_std``, ``from_std_rad``. Empty for a calm sea."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(SEA_KEY, *stream)))
    out = []
    systems = []
    if waves.hs_m > 0.0:
        wp = peak_frequency(waves.spectrum, waves.gamma, tp=waves.tp_s, tz=waves.tz_s, t1=waves.t1_s)
        systems.append((waves.hs_m, 2.0 * math.pi / wp, waves.gamma if waves.spectrum == "jonswap" else None,
                        waves.direction_deg))
    if waves.swell_hs_m > 0.0:
        systems.append((waves.swell_hs_m, waves.swell_tp_s, waves.swell_gamma, waves.swell_direction_deg))
    for hs, tp, gamma, frm in systems:
        e = rng.standard_normal(3)
        out.append({"hs_m": float(hs * (1.0 + HS_REL_STD * e[0])), "tp_s": float(tp * (1.0 + TP_REL_STD * e[1])),
                    "gamma": None if gamma is None else float(gamma),
                    "from_rad": float(math.radians(frm) + DIRECTION_STD_RAD * e[2]),
                    "hs_rel_std": HS_REL_STD, "tp_rel_std": TP_REL_STD, "from_std_rad": DIRECTION_STD_RAD})
    return out

"""The planner's short markdown report."""

from __future__ import annotations


def _f(x, fmt=".4f"):
    return "—" if x is None else format(x, fmt)


def markdown(doc: dict) -> str:
    tg = doc["target"]
    u = tg["unit"]
    setting = ", ".join(f"{k} {v}" for k, v in tg["setting"].items())
    rule = ("empirical quantile of |error| within the tolerance (fraction within ≥ confidence)"
            if tg["rule"] == "quantile" else "Wilson lower bound of the fraction within the tolerance ≥ confidence")
    L = [f"# Trial plan: {doc['kind']} of {doc['ship']} ({doc['plan']})", "",
         f"Target: {tg['quantity']} at the spot ({setting}) within ±{tg['tolerance']:g} {u} "
         f"at {100 * tg['confidence']:g} % (rule: {rule}).",
         f"Limits: trial time ≤ {doc['limits']['max_hours']:g} h"
         + (f", wind ≤ {doc['limits']['max_wind_kn']:g} kn" if doc['limits']['max_wind_kn'] is not None else "") + ".",
         "Site climate (drawn per replicate): " + "; ".join(f"{k} {v}" for k, v in doc["climate"].items()) + ".",
         f"Search: campaigns of {doc['search_replicates']} replicates, in this order: "
         + ", ".join(doc["search_order"]) + f". Surrogate {doc['surrogate']['model']}, error shape "
         + (f"empirical ({100 * tg['confidence']:g} % quantile of |e|/√MSE = {doc['surrogate']['shape_quantile']:.3f} "
            f"from {doc['surrogate']['shape_pool']} search replicates; 1.960 for normal errors)"
            if doc["surrogate"].get("shape_quantile") is not None else "normal") + ".", ""]
    if doc["chosen"] is None:
        L.append("**The search ended without an agenda that meets the target** (none of the family within the limits "
                 "is predicted to, or the search was stopped first).")
    else:
        L += [f"**Chosen agenda: {doc['chosen']}** — one step cheaper: {doc['one_step_cheaper'] or 'none'}.", "",
              f"| agenda | trial time predicted / simulated [h] | {100 * tg['confidence']:g} % quantile of abs(error) "
              f"predicted / search / verified [{u}] | fraction within ±{tg['tolerance']:g} {u} (verified, Wilson 95 %) "
              f"| meets (verified) |",
              "|---|---|---|---|---|"]
        for role in ("chosen", "one_step_cheaper"):
            v = doc["verification"].get(role)
            if v is None:
                continue
            c, p, s, r = v["candidate"], v["predicted"], v["search"], v["verified"]
            L.append(f"| {role.replace('_', ' ')}: {c['name']} ({c['describe']}) | {c['predicted_trial_time_s'] / 3600:.2f} / "
                     f"{r['simulated_time_s'] / 3600:.2f} | {_f(p and p['quantile_abs_error'])} / "
                     f"{_f(s and s['quantile_abs_error'])} / {r['quantile_abs_error']:.4f} | "
                     f"{r['within']}/{r['n']} = {r['fraction']:.3f} [{r['wilson_lo']:.3f}, {r['wilson_hi']:.3f}] | "
                     f"{'yes' if r['meets'] else 'no'} |")
        L += ["", f"Verified errors: " + "; ".join(
            f"{v['candidate']['name']}: mean {v['verified']['mean_error']:+.4f} {u}, rms {v['verified']['rms_error']:.4f} {u}"
            + (f" (surrogate rms {v['predicted']['mse'] ** 0.5:.4f} {u})" if v.get("predicted") else "")
            for v in doc["verification"].values()) + "."]
        a = doc["acceptance"]
        short = [f"{v['candidate']['name']} has {v['verified']['n']} of its {v['verified'].get('planned_replicates', v['verified']['n'])}"
                 for v in doc["verification"].values()
                 if v["verified"]["n"] < v["verified"].get("planned_replicates", v["verified"]["n"])]
        if short:
            L += ["", "**Verification stopped short:** " + "; ".join(short) + " planned replicates (summarized over "
                  "the replicates run)."]
        L += ["", f"Verified with {doc['verify_replicates']} planned replicates (independent seed): chosen meets the target: "
                  f"{a['chosen_meets']}; the one-step-cheaper agenda fails it: {a['cheaper_fails']}."]
    L += ["", "## Candidates (cheapest first)", "",
          f"| agenda | trial time [h] | predicted quantile [{u}] | predicted meets | search quantile [{u}] | search within |",
          "|---|---|---|---|---|---|"]
    for c in doc["candidates"]:
        p, s = c["predicted"], c["search"]
        L.append(f"| {c['name']} | {c['predicted_trial_time_s'] / 3600:.2f} | {_f(p and p['quantile_abs_error'])} | "
                 f"{'—' if p is None else ('yes' if p['meets'] else 'no')} | {_f(s and s['quantile_abs_error'])} | "
                 f"{'—' if s is None else str(s['within']) + '/' + str(s['n'])} |")
    return "\n".join(L) + "\n"

"""Sentences with numbers, drawn from a study's results."""

from __future__ import annotations

__all__ = ["findings"]


def _at_spp(series: dict, spp: int):
    for p in series["points"]:
        if p["spp"] == spp:
            return p
    return None


def findings(scene_name: str, study: dict, *, compare_spp: int = 64) -> list[str]:
    out = []
    thin = study["models"].get("thin")
    if thin and "random" in thin:
        base = _at_spp(thin["random"], compare_spp)
        if base:
            ranked = sorted(((s["points"], name) for name, s in thin.items()),
                            key=lambda item: (_at_spp({"points": item[0]}, compare_spp) or {"relative_rmse": 9e9})[
                                "relative_rmse"])
            parts = []
            for points, name in ranked:
                p = _at_spp({"points": points}, compare_spp)
                if p:
                    ratio = (f"{base['relative_rmse'] / p['relative_rmse']:.2f}x lower than random"
                             if p["relative_rmse"] > 0 else "no error left")
                    parts.append(f"{name} {100 * p['relative_rmse']:.2f} % in {p['seconds']:.2f} s ({ratio})")
            out.append(f"{scene_name}, thin lens (defocus) at {compare_spp} spp: " + "; ".join(parts) + ".")
        slopes = ", ".join(f"{name} {s['slope']:.2f}" for name, s in thin.items() if s["slope"] is not None)
        out.append(f"{scene_name}, thin lens: error falls as N^slope with slope {slopes} "
                   "(plain Monte Carlo: -0.50).")
    steps = []
    for model, series in study["models"].items():
        times = [s["seconds_to_1_percent"]["seconds"] for s in series.values()
                 if s["seconds_to_1_percent"]["seconds"] is not None]
        best = min(times) if times else None
        err = study["model_error_vs_lens"].get(model)
        steps.append(f"{model}: {best:.2f} s to 1 % noise" if best is not None else f"{model}: 1 % not reached")
        if err:
            steps[-1] += f", {100 * err['relative_rmse']:.1f} % from the full lens system"
            left_out = [f"{name} {e['magnitude']:.3g} {e['unit']}" for name, e in err.get("omitted_effects", {}).items()
                        if e["magnitude"] > 0]
            if left_out:
                steps[-1] += " (leaves out " + ", ".join(left_out) + ")"
    if steps:
        out.append(f"{scene_name}, cost of each model (best sampler): " + "; ".join(steps) + ".")
    pov = study.get("povray")
    if pov and pov.get("seconds_to_1_percent", {}).get("seconds") and thin:
        native = min(s["seconds_to_1_percent"]["seconds"] for s in thin.values()
                     if s["seconds_to_1_percent"]["seconds"] is not None)
        out.append(f"{scene_name}: POV-Ray focal blur needs {pov['seconds_to_1_percent']['seconds']:.2f} s to reach "
                   f"1 % against the native thin lens's converged image; the native thin lens needs {native:.2f} s "
                   f"({pov['seconds_to_1_percent']['seconds'] / native:.1f}x faster).")
    return out

"""The report page: static HTML that opens from disk, images beside it."""

from __future__ import annotations

import html
import json

__all__ = ["render_page", "SECTIONS"]

_RENDERER_SUFFIX = {"povray": " · POV-Ray", "mitsuba": " · Mitsuba"}
_RENDERER_LABEL = {"povray": " (POV-Ray)", "mitsuba": " (Mitsuba)"}

SECTIONS = [
    ("images", "Images, model by model"),
    ("blur", "Blur disks against equation 5"),
    ("distortion", "Distortion"),
    ("vignetting", "Vignetting"),
    ("povray", "Agreement with POV-Ray"),
    ("mitsuba", "Agreement with Mitsuba 3"),
    ("model-error", "Model error against the full lens system"),
    ("time", "Time per render"),
    ("cost", "What accuracy costs in time"),
    ("plan", "Effects each scene needs: predicted and measured"),
    ("chromatic", "Chromatic aberration"),
    ("figures", "Teaching figures"),
    ("provenance", "Provenance"),
]

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { border: 1px solid #ddd; padding: 0.25em 0.6em; text-align: right; }
th { background: #f4f4f4; } td.l, th.l { text-align: left; }
.grid { display: flex; flex-wrap: wrap; gap: 0.8em; }
figure { margin: 0; } figure img { display: block; max-width: 360px; image-rendering: pixelated; border: 1px solid #ccc; }
figcaption { font-size: 0.85em; text-align: center; }
img.plot { max-width: 100%; }  /* plots are drawn at the size they are read at */ .note { color: #555; font-size: 0.9em; }
nav a { margin-right: 1em; }
"""


def _fmt(value, digits=4):
    if value is None:
        return "–"
    if isinstance(value, float):
        if value != value:
            return "–"
        if abs(value) >= 1e5 or (0 < abs(value) < 1e-3):
            return f"{value:.3e}"
        return f"{value:.{digits}g}"
    return html.escape(str(value))


def _table(header, rows, left=1):
    out = ["<table><tr>" + "".join(f'<th class="{"l" if i < left else ""}">{html.escape(h)}</th>'
                                   for i, h in enumerate(header)) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join(f'<td class="{"l" if i < left else ""}">{_fmt(c)}</td>' for i, c in enumerate(row))
                   + "</tr>")
    return "".join(out) + "</table>"


def _measured_effects(scene_entry) -> dict:
    """Effect sizes this report measured, in the planner's units."""
    out = {}
    blur = scene_entry.get("blur_disks", {}).get("renders", {}).get("thin")
    if blur:
        out["defocus"] = max((r["measured_px"] for r in blur if r), default=None)
    vig = scene_entry.get("vignetting", {}).get("renders", {}).get("lens")
    if vig and vig["relative_illumination"]:
        out["vignetting"] = 100.0 * (1.0 - vig["relative_illumination"][-1])
    return out


def _traced_at(data: dict, angle: float):
    traced = data.get("traced")
    if not traced or angle not in traced["field_deg"]:
        return None
    return traced["relative_illumination"][traced["field_deg"].index(angle)]


def _seconds_cell(seconds, extrapolated: bool) -> str:
    if seconds is None:
        return "not reached"
    return f"{seconds:.3g} (extrapolated)" if extrapolated else f"{seconds:.3g}"


def chromatic_body(section: dict | None) -> str:
    """The chromatic section's HTML: the note, the table of sizes and the figure."""
    if not section:
        return "<p>No chromatic section in this report.</p>"
    rows = [[r["scene"], r["lens"], "yes" if r["disperses"] else "no", r["chromatic_focal_shift_mm"],
             r["lateral_color_px"], r["measured_lateral_color_px"], r["longitudinal_color_px"],
             r["measured_longitudinal_color_px"]] for r in section["rows"]]
    body = (f"<p class='note'>{html.escape(section['note'])}</p>"
            + _table(["scene", "lens", "disperses", "F−C focal shift (mm)", "lateral colour (px)", "measured",
                      "longitudinal colour (px)", "measured"], rows, 3))
    if section.get("figure"):
        body += (f"<figure><img class='plot' src='{html.escape(section['figure'])}' alt='chromatic'>"
                 "<figcaption>ray fans at F, d, C and the focal shift against wavelength</figcaption></figure>")
    return body


def _section(key, body):
    title = dict(SECTIONS)[key]
    return f'<section id="{key}"><h2>{html.escape(title)}</h2>{body}</section>'


def render_page(results: dict) -> str:
    scenes = results["scenes"]
    parts = [f"<!doctype html><html lang='en'><head><meta charset='utf-8'><title>lenscompare report</title>"
             f"<style>{_STYLE}</style></head><body>",
             "<h1>lenscompare report</h1>",
             f"<p class='note'>{html.escape(results['provenance']['created'])} · lens "
             f"{html.escape(results['settings']['lens'])} · {'quick' if results['settings']['quick'] else 'full'} run"
             f" · {len(results['renders'])} renders in {results['total_seconds']:.1f} s</p>",
             "<nav>" + "".join(f'<a href="#{k}">{html.escape(t)}</a>' for k, t in SECTIONS) + "</nav>"]
    notes = [n for s in scenes.values() for n in s["notes"]] + results.get("notes", [])
    if notes:
        parts.append("<ul class='note'>" + "".join(f"<li>{html.escape(n)}</li>" for n in dict.fromkeys(notes))
                     + "</ul>")

    body = []
    for name, s in scenes.items():
        r = s["rendered"]
        rendered = (f"Rendered through {r['lens']} at f/{r['f_number']:g}, focused at {r['focus_distance_m']:g} m, "
                    f"{r['resolution'][0]}×{r['resolution'][1]} px, {r['spp']} spp"
                    + (f" (POV-Ray {r['povray_spp']})" if r.get("povray_spp") else "")
                    + (f" (Mitsuba {r['mitsuba_spp']})" if r.get("mitsuba_spp") else "") + ".")
        body.append(f"<h3>{html.escape(name)}</h3><p class='note'>{html.escape(s['description'])}</p>"
                    f"<p class='note'><strong>{html.escape(rendered)}</strong></p><div class='grid'>")
        for r in s["renders"]:
            label = r["model"] + _RENDERER_SUFFIX.get(r["renderer"], "")
            body.append(f"<figure><img src='{html.escape(r['png'])}' alt='{html.escape(name)} {html.escape(label)}'>"
                        f"<figcaption>{html.escape(label)} · {r['seconds']:.2f} s</figcaption></figure>")
        body.append("</div>")
    parts.append(_section("images", "".join(body)))

    body = []
    for name, s in scenes.items():
        blur = s.get("blur_disks")
        if not blur:
            continue
        body.append(f"<img class='plot' src='{html.escape(blur['plot'])}' alt='blur diameter against depth'>")
        rows = []
        for label, entries in blur["renders"].items():
            for e in entries:
                if e:
                    rows.append([label, e["depth_m"], e["field_deg"], e["measured_px"], e["eq5_px"],
                                 e["departure_from_eq5_percent"], e["expected_px"], e["expected_from"],
                                 e["error_percent"]])
        body.append("<p class='note'>Second-moment diameters (corrected for pixel footprint and source size). "
                    "Departure from eq. 5 is what the model does to the blur; the error is against what that model "
                    "should give: eq. 5 for the ideal models, a real-ray spot traced through the prescription at "
                    "the same depth and field for the lens system (pupil vignetting and aberrations make its blur "
                    "depart from eq. 5 off the axis).</p>")
        body.append(_table(["render", "depth (m)", "field (°)", "measured (px)", "eq. 5 (px)",
                            "departure from eq. 5 (%)", "expected (px)", "expected from", "error (%)"], rows))
    parts.append(_section("blur", "".join(body) or "<p>No blur-disk scene in this report.</p>"))

    body = []
    for name, s in scenes.items():
        d = s.get("distortion")
        if not d:
            continue
        body.append(f"<img class='plot' src='{html.escape(d['plot'])}' alt='distortion against field angle'>")
        body.append(f"<p class='note'>Distortion: {html.escape(d['definition'])}.</p>")
        rows = [[label, v["f_number"], v["max_abs_distortion_percent"], v["k1"], v["k2"],
                 f"{v['dots_matched']}/{v['dots_in_scene']}"] for label, v in d["renders"].items() if v]
        body.append(_table(["render", "f-number", "max |distortion| (%)", "k1", "k2", "dots matched"], rows))
    parts.append(_section("distortion", "".join(body) or "<p>No dot-grid scene in this report.</p>"))

    body = []
    for name, s in scenes.items():
        v = s.get("vignetting")
        if not v:
            continue
        body.append(f"<img class='plot' src='{html.escape(v['plot'])}' alt='relative illumination'>")
        rows = [[label, data["f_number"], data["at"].get("10_deg"), data["at"].get("20_deg"),
                 _traced_at(data, 10.0), _traced_at(data, 20.0)] for label, data in v["renders"].items() if data]
        body.append(_table(["render", "f-number", "RI at 10°", "RI at 20°", "real-ray trace at 10°",
                            "real-ray trace at 20°"], rows))
    parts.append(_section("vignetting", "".join(body) or "<p>No flat-field scene in this report.</p>"))

    rows = [[name, model, c["ssim"], c["relative_rmse"], c["psnr_db"], c["ciede2000_mean"]]
            for name, s in scenes.items() for model, c in s.get("vs_povray", {}).items()]
    parts.append(_section("povray", "<p class='note'>Native render against POV-Ray's render of the same scene "
                          "(POV-Ray is the reference).</p>"
                          + _table(["scene", "model", "SSIM", "relative RMSE", "PSNR (dB)", "ΔE00 mean"], rows, 2)))

    rows = [[name, model, c["ssim"], c["relative_rmse"], c["psnr_db"], c["ciede2000_mean"]]
            for name, s in scenes.items() for model, c in s.get("vs_mitsuba", {}).items()]
    parts.append(_section("mitsuba", "<p class='note'>Native render against Mitsuba 3's render of the same scene "
                          "(scalar_rgb, exported as by <code>lenscompare export --to mitsuba</code>; Mitsuba is the "
                          "reference). Scenes whose lights have no inverse-square falloff are not rendered by "
                          "Mitsuba (see the notes).</p>"
                          + _table(["scene", "model", "SSIM", "relative RMSE", "PSNR (dB)", "ΔE00 mean"], rows, 2)))

    rows = [[name, model, c["ssim"], c["relative_rmse"], c["psnr_db"], c["ciede2000_mean"]]
            for name, s in scenes.items() for model, c in s.get("vs_lens", {}).items()]
    parts.append(_section("model-error", "<p class='note'>Each cheaper model against the full lens system on the "
                          "same lens (the lens image is film irradiance, so vignetting counts as model error).</p>"
                          + _table(["scene", "model", "SSIM", "relative RMSE", "PSNR (dB)", "ΔE00 mean"], rows, 2)))

    rows = [[r["scene"], r["model"] + _RENDERER_LABEL.get(r["renderer"], ""), r["spp"], r["seconds"],
             r["samples_per_second"]] for r in results["renders"]]
    parts.append(_section("time", f"<img class='plot' src='{html.escape(results['time_plot'])}' alt='render times'>"
                          + _table(["scene", "render", "spp", "seconds", "samples/s"], rows, 2)))

    cost = results.get("cost")
    if cost:
        body = ("<ul>" + "".join(f"<li>{html.escape(f)}</li>" for f in cost["findings"]) + "</ul>"
                + f"<img class='plot' src='{html.escape(cost['plot'])}' alt='error against time'>"
                + "<p class='note'>Seconds to 1 % relative RMSE against the converged image. A time marked "
                  "<em>extrapolated</em> was not reached at this report's sample counts: it extends the last two "
                  "renders' slope (run <code>lenscompare cost</code> without --quick to measure it).</p>"
                + _table(["scene", "model", "sampler", "seconds to 1 % RMSE"],
                         [[s, m, k, _seconds_cell(t, x)] for s, m, k, t, x in cost["time_to_1_percent"]], 3)
                + f"<p><a href='{html.escape(cost['index'])}'>The whole study</a></p>")
    else:
        body = "<p>No cost study in this report.</p>"
    parts.append(_section("cost", body))

    rows = []
    for name, s in scenes.items():
        plan = s.get("plan")
        if not plan:
            continue
        measured = _measured_effects(s)
        for effect, e in plan["effects"].items():
            rows.append([name, effect, e["magnitude"], e["unit"], measured.get(effect), "yes" if e["needed"] else "no"])
        how = ", ".join(f"{k} {'on' if v is True else v}" for k, v in plan.get("lens_options", {}).items())
        rows.append([name, f"→ model {plan['model']}" + (f" ({how})" if how else ""), plan.get("time_saved_seconds"),
                     "s saved vs lens, equal spp", None, ""])
        rows.append([name, "", plan.get("time_saved_at_equal_noise_seconds"), "s saved vs lens, equal noise", None,
                     ""])
    parts.append(_section("plan", "<p class='note'>Predicted from the scene alone (lenscompare plan); measured from "
                          "this report's renders where the scene measures that effect.</p>"
                          + _table(["scene", "effect", "predicted", "unit", "measured", "needed"], rows, 2)))

    parts.append(_section("chromatic", chromatic_body(results.get("chromatic"))))

    figures = results.get("teaching_figures", {})
    body = "".join(f"<figure><img class='plot' src='{html.escape(p)}' alt='{html.escape(k)}'>"
                   f"<figcaption>{html.escape(k)}</figcaption></figure>" for k, p in figures.items())
    parts.append(_section("figures", body or "<p>Teaching figures were not drawn.</p>"))

    parts.append(_section("provenance", "<pre>" + html.escape(json.dumps(results["provenance"], indent=2))
                          + "</pre>"))
    # Counts loaded images on the body (checked by the headless-browser test).
    parts.append("<script>window.addEventListener('load', function () { var ok = 0; "
                 "for (var i = 0; i < document.images.length; i++) { var im = document.images[i]; "
                 "if (im.complete && im.naturalWidth > 0) ok++; } "
                 "document.body.setAttribute('data-images-loaded', ok); "
                 "document.body.setAttribute('data-images-total', document.images.length); });</script>")
    parts.append("</body></html>")
    return "\n".join(parts)

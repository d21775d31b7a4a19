"""``make report``: results/report.html, one self-contained page (figures embedded, no network)
with our figures and tables beside the paper's values and the provenance of every run."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

import pandas as pd

from rover_cosim.common.paper import TABLE_3_RMS as PAPER_RMS


def _image(path: Path, caption: str) -> str:
    if not path.exists():
        return f"<p class='missing'>{html.escape(caption)}: {html.escape(str(path))} not produced.</p>"
    data = base64.b64encode(path.read_bytes()).decode()
    return (f"<figure><img src='data:image/png;base64,{data}' alt='{html.escape(caption)}'>"
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def _table(frame: pd.DataFrame) -> str:
    return frame.to_html(index=False, float_format=lambda v: f"{v:.3g}", border=0, classes="data")


def _provenance(path: Path) -> str:
    if not path.exists():
        return f"<p class='missing'>{html.escape(str(path))} not produced.</p>"
    record = json.loads(path.read_text())
    keep = {k: record[k] for k in ("command", "created_utc", "git_commit", "versions", "parameters", "fmu_sha256",
                                   "fmus", "model_sha256", "wall_seconds", "run_wall_seconds", "sweep_wall_seconds",
                                   "runs_computed", "runs_cached", "runs_failed") if k in record}
    text = html.escape(json.dumps(keep, indent=2))
    return f"<details><summary>{html.escape(path.name)}</summary><pre>{text}</pre></details>"


def _lateral_section(identification: Path) -> list[str]:
    """The identified lateral model: Fits off the grid, the forms tried, Ishigami's trends."""
    sections = ["<h2>Lateral force (the paper's future work): Fy(W, beta, slip)</h2>",
                ("<p>Ishigami et al. (2007)'s side force in the wheel (lateral shear and sidewall bulldozing), "
                 "identified like Sec. 3 from torque steps on the test bed with its carriage at slip angles "
                 "0-30 deg. Model: Fy = sum c<sub>ik</sub>(W) phi<sub>i</sub>(beta) slip<sup>k</sup>, "
                 "phi<sub>i</sub> = beta/(|beta| + beta<sub>i</sub>), c<sub>ik</sub> quadratic in W. "
                 "Validation (Eq. 15) at loads and slip angles off the sweep's grid, the track turning "
                 "between +beta and -beta while the torque steps 5-40 N·m.</p>")]
    fits, forms, trends = (identification / f"lateral_{name}.csv" for name in ("fit_table", "forms", "trends"))
    if not fits.exists():
        return [*sections, f"<p class='missing'>{html.escape(str(fits))} not produced.</p>"]
    table = pd.read_csv(fits).rename(columns={
        "load_N": "load [N]", "slip_angle_deg": "slip angle [deg]", "fit_percent": "Fit [%]",
        "max_settled_error_N": "largest settled error [N]", "max_settled_error_percent": "largest settled error [%]"})
    sections.append(_table(table))
    if forms.exists():
        tried = pd.read_csv(forms)[["form", "coefficients", "training_rms_N", "min_fit_percent"]]
        sections += ["<p>Forms tried (the first is used):</p>", _table(tried.rename(columns={
            "training_rms_N": "RMS on the sweep [N]", "min_fit_percent": "lowest Fit [%]"}))]
    if trends.exists():
        measured = pd.read_csv(trends).rename(columns={"trend": "Ishigami et al. 2007 report", "holds": "ours",
                                                       "measured": "measured on our sweep"})
        sections += ["<p>The trends Ishigami et al. report from their single-wheel experiments:</p>",
                     _table(measured)]
    for name, caption in (("fig_lateral_fy.png", "Fy against slip angle and slip, sweep and model"),
                          ("fig_lateral_coefficients.png", "coefficients c_ik(W) of the lateral model"),
                          ("fig_lateral_validation_575N.png", "lateral validation at 575 N, ±12.5 deg")):
        sections.append(_image(identification / name, caption))
    return sections


def _path_section(simulation: Path) -> list[str]:
    """The steerable rover following the turn and the lane change."""
    sections = ["<h2>Path following: the steerable rover with the identified Fx and Fy models</h2>",
                ("<p>SteerableRover (body in x, y, yaw with heave, pitch, roll; every wheel driven and "
                 "steered). Path tracking at the body gives a force and yaw-moment demand, allocated to the "
                 "wheels by least squares weighted by their loads; per wheel the inverse identified lateral "
                 "model gives the steering angle and the inverse longitudinal model the torque. Turn: 10 m, "
                 "90 deg of radius 10 m, 10 m at 0.5 m/s; lane change: 3 m over 15 m at 1.0 m/s. Ablation: "
                 "kinematic steering (wheels along the commanded hub velocities, no slip-angle "
                 "compensation).</p>")]
    metrics, agreement = simulation / "path_metrics.csv", simulation / "path_agreement.csv"
    if not metrics.exists():
        return [*sections, f"<p class='missing'>{html.escape(str(metrics))} not produced.</p>"]
    table = pd.read_csv(metrics)
    shown = pd.DataFrame({
        "scenario": table["scenario"].str.replace("_", " "),
        "run": table["run"].map({"inverse": "identified models, SteerableRover.fmu",
                                 "cosim": "identified models, co-simulated", "kinematic": "kinematic steering"}),
        "cross-track RMS [cm]": 100 * table["cross_track_rms_m"],
        "cross-track max [cm]": 100 * table["cross_track_max_m"],
        "speed error max [%]": table["speed_error_max_percent"],
        "RMS(Fx - Fx_des), worst wheel [N]": table.filter(like="rms_Fx").max(axis=1),
        "RMS(Fy - Fy_des), worst wheel [N]": table.filter(like="rms_Fy").max(axis=1)})
    sections += ["<p>Floors of the issue: cross-track RMS &lt; 10 cm, max &lt; 30 cm, speed within 5 %, "
                 "force errors &lt; 2 N per wheel (every wheel's value in <code>path_metrics.csv</code>).</p>",
                 _table(shown)]
    if agreement.exists():
        agree = pd.read_csv(agreement).rename(columns={
            "speed_max_difference_percent": "speed, largest difference [% of target]",
            "load_max_difference_percent": "loads, largest difference [% of static]",
            "path_max_difference_m": "path, largest distance [m]"})
        sections += ["<p>Monolithic against co-simulated (SteerableRoverBody + 6 Wheel):</p>", _table(agree)]
    sections += [_image(simulation / "path_xy.png", "paths in the plane and cross-track error"),
                 _image(simulation / "path_wheels_turn.png", "turn: wheel forces, slip angles, steering, loads"),
                 _image(simulation / "path_wheels_lane_change.png", "lane change: wheel forces, slip angles, loads")]
    return sections


def build_report(results: Path) -> str:
    identification = results / "identification"
    simulation = results / "simulation"
    sections = ["<h1>rover-cosim: reproduction of Yoshikawa et al.</h1>",
                ("<p>Every number below is read from the files under <code>results/</code> written by "
                 "<code>make run</code>; the paper's values are quoted beside ours.</p>")]

    sections += ["<h2>Fig. 3: Fx against slip (numpy reference wheel)</h2>",
                 _image(results / "fig3_fx_vs_slip.png", "Fx(slip) for loads 100-800 N")]

    sections.append("<h2>Identification (Sec. 3): Table 1</h2>")
    models = identification / "fit_models.csv"
    if models.exists():
        fits = pd.read_csv(models)
        table = pd.DataFrame({"load [N]": fits["load_N"], "paper Fit [%]": fits["paper_fit_percent"],
                              "ours, linear Eq. (14) [%]": fits["fit_percent_linear"],
                              "ours, quadratic (recommended) [%]": fits["fit_percent_quadratic"]})
        sections.append(_table(table))
    else:
        sections.append(f"<p class='missing'>{models} not produced.</p>")
    for name, caption in (("fig5_fx_vs_slip.png", "Fig. 5: settled Fx against slip with Fx = a(W) slip + b(W)"),
                          ("fig6_a_of_W.png", "Fig. 6: a(W)"), ("fig7_b_of_W.png", "Fig. 7: b(W)"),
                          ("fig8_validation_575N.png", "Fig. 8: identified model against the FMU at 575 N")):
        sections.append(_image(identification / name, caption))
    sections += _lateral_section(identification)

    sections.append("<h2>Closed loop (Sec. 4): Table 3 and Fig. 10</h2>")
    rms_path, cosim_path = simulation / "rms.csv", simulation / "rms_cosim.csv"
    if rms_path.exists() and cosim_path.exists():
        ours, cosim = pd.read_csv(rms_path), pd.read_csv(cosim_path)
        paper = [PAPER_RMS.get(i, float("nan")) for i in ours["limb"]]
        table = pd.DataFrame({"limb": ours["limb"], "paper RMS [N]": paper,
                              "ours, Rover.fmu [N]": ours["rms_N"], "ours, RoverBody + 6 Wheel [N]": cosim["rms_N"]})
        sections.append(_table(table))
    ablation = simulation / "ablation_fixed_load.csv"
    if ablation.exists():
        sections += [("<p>Ablation: the same controller with one model at a fixed 424 N instead of the per-load "
                      "look-up tables:</p>"), _table(pd.read_csv(ablation))]
    record_path = simulation / "simulation.json"
    if record_path.exists():
        checks = json.loads(record_path.read_text()).get("checks", {})
        rows = [{"plant": plant, **values} for plant, values in checks.items()]
        sections += ["<p>Velocity (paper: the rover reaches 1.0 m/s, Fig. 10 g):</p>", _table(pd.DataFrame(rows))]
    sections += [_image(simulation / "fig10_closed_loop.png", "Fig. 10 (a)-(h), Rover.fmu"),
                 _image(simulation / "fig10_closed_loop_cosim.png", "Fig. 10 (a)-(h), RoverBody + 6 Wheel")]

    sections += _path_section(simulation)

    study = results / "cosim_study" / "coupling_error.png"
    if study.exists():
        sections += ["<h2>Co-simulation coupling error</h2>", _image(study, "co-simulated vs monolithic rover")]

    sections.append("<h2>Provenance</h2>")
    for path in (results / "fig3_fx_vs_slip.json", identification / "identification.json", record_path,
                 simulation / "path_following.json"):
        sections.append(_provenance(path))
    style = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
             "img{max-width:100%}table.data{border-collapse:collapse;margin:1em 0}"
             "table.data td,table.data th{border:1px solid #bbb;padding:4px 8px;text-align:right}"
             ".missing{color:#a00}pre{background:#f6f6f6;padding:1em;overflow:auto}")
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>rover-cosim report</title>"
            f"<style>{style}</style></head><body>" + "\n".join(sections) + "</body></html>\n")

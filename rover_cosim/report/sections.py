"""The sections of the report, each from the files one job wrote (a section whose files are
missing says so): soil and wheel (Table 2), Fig. 3, identification (Table 1), the lateral force,
the closed loop (Table 3, Fig. 10, tracking), path following, the coupling study, Monte Carlo
over soil uncertainty, behaviour outside the paper's scope, provenance."""

from __future__ import annotations

import html
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import pandas as pd

from rover_cosim.common.paper import TABLE_3_RMS as PAPER_RMS
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.jobs.simulate import CHECKS
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.parameters import ROVER_UNITS, Rover

from .page import image, missing, provenance, read_record, table

#: Units and names of the soil and wheel parameters (Table 2).
PARAMETERS = {"c": ("cohesion c", "Pa"), "phi": ("friction angle φ", "deg"), "kc": ("k_c", "N/m^(n+1)"),
              "kphi": ("k_φ", "N/m^(n+2)"), "n": ("sinkage exponent n", "-"), "kx": ("shear modulus k_x", "m"),
              "a0": ("a0", "-"), "a1": ("a1", "-"), "lam": ("exit-angle ratio λ", "-"),
              "kx_beta": ("k_x growth with β", "m/rad"), "ky": ("lateral shear modulus k_y", "m"),
              "ky_beta": ("k_y growth with β", "m/rad"), "rho": ("dry density ρ", "kg/m³"),
              "gravity": ("gravity on the soil", "m/s²"), "xc": ("destructive angle X_c", "deg"),
              "r": ("wheel radius r", "m"), "b": ("wheel width b", "m"), "J": ("wheel inertia J", "kg·m²")}
ANGLES = {"phi", "xc"}


def _record(*paths: Path) -> dict[str, Any]:
    """The first of the records that exists (soil and wheel are in every job's record)."""
    for path in paths:
        if path.exists():
            record = read_record(path)
            if "soil" in record:
                return record
            choice = record.get("parameters", {}).get("choice")
            if choice:
                return choice
    return {}


def soil_record(results: Path) -> dict[str, Any]:
    """The soil and wheel the results were made with (from the jobs' records; {} if none say)."""
    return _record(results / "identification" / "identification.json", results / "simulation" / "simulation.json",
                   *sorted(results.glob("fig3_fx_vs_slip*.json")))


def fig3_file(results: Path, suffix: str) -> Path:
    """Fig. 3's file (``suffix``: csv, png, json) of the results' soil and wheel: the one whose
    record names them, else fig3_fx_vs_slip.<suffix>."""
    record = soil_record(results)
    soil, wheel = record.get("soil", {}).get("name"), record.get("wheel", {}).get("name")
    for path in sorted(results.glob("fig3_fx_vs_slip*.json")):
        choice = read_record(path).get("parameters", {}).get("choice", {})
        if choice.get("soil", {}).get("name") == soil and choice.get("wheel", {}).get("name") == wheel:
            return path.with_suffix(f".{suffix}")
    return results / f"fig3_fx_vs_slip.{suffix}"


def on_paper_soil(results: Path) -> bool:
    """Whether the results are on the paper's soil, wheel (Table 2, unchanged) and rover: only then
    are the paper's numbers set beside ours."""
    record = soil_record(results)
    soil, wheel = record.get("soil", {}), record.get("wheel", {})
    paper_soil = soil.get("values", asdict(Soil())) == asdict(Soil())
    paper_rover = record.get("rover", {}).get("name", "paper") == "paper"
    return (paper_soil and paper_rover and wheel.get("values", asdict(Wheel())) == asdict(Wheel())
            and not record.get("set"))


def soil_label(results: Path) -> str:
    """"soil NAME, wheel NAME[, rover NAME]" of the results (not escaped; the rover where it is not
    the paper's)."""
    record = soil_record(results)
    rover = record.get("rover", {}).get("name", "paper")
    return (f"soil {record.get('soil', {}).get('name', 'paper')}, "
            f"wheel {record.get('wheel', {}).get('name', 'paper')}" + (f", rover {rover}" if rover != "paper" else ""))


def soil_section(results: Path) -> list[str]:
    """Table 2: the soil and wheel in use beside the paper's."""
    record = soil_record(results)
    soil, wheel = record.get("soil", {}), record.get("wheel", {})
    used = {**soil.get("values", asdict(Soil())), **wheel.get("values", asdict(Wheel()))}
    paper = {**asdict(Soil()), **asdict(Wheel())}
    rows = []
    for key, (label, unit) in PARAMETERS.items():
        convert = math.degrees if key in ANGLES else float
        rows.append({"parameter": label, "unit": unit, "paper (Table 2, Ishigami 2007)": convert(paper[key]),
                     "in use": convert(used.get(key, paper[key]))})
    name = html.escape(f"{soil.get('name', 'paper')}: {soil.get('title') or 'the paper’s soil'}")
    wheel_name = html.escape(f"{wheel.get('name', 'paper')}: {wheel.get('title') or 'the paper’s wheel'}")
    changed = html.escape(", ".join(map(str, record.get("set") or [])))
    source = html.escape(str(soil.get("source") or "paper Table 2"))
    return ["<h2>Soil, wheel and rover in use (Table 2)</h2>",
            f"<p>Soil <b>{name}</b>; wheel <b>{wheel_name}</b>" + (f"; changed with {changed}" if changed else "")
            + f". Source: {source}.</p>",
            table(pd.DataFrame(rows), default="{:.4g}"), *rover_rows(record)]


def rover_rows(record: dict[str, Any]) -> list[str]:
    """The rover in use (a record's ``rover``): its values beside the paper's, its wheel count and
    static wheel load; nothing for a record without one."""
    rover = record.get("rover")
    if not rover:
        return []
    values, paper = rover.get("values", {}), asdict(Rover())
    gravity = record.get("soil", {}).get("values", {}).get("gravity", Soil().gravity)

    def shown(value: Any) -> str:
        return ", ".join(f"{v:g}" for v in value) if isinstance(value, (list, tuple)) else f"{value:.4g}"

    rows = [{"parameter": key, "unit": ROVER_UNITS.get(key, ""), "paper's rover": shown(paper[key]),
             "in use": shown(values.get(key, paper[key]))} for key in paper]
    mass, wheels = float(values.get("mass", paper["mass"])), int(rover.get("wheels", 6))
    title = html.escape(f"{rover.get('name', 'paper')}: {rover.get('title') or 'the paper’s rover'}")
    source = html.escape(str(rover.get("source") or "paper Sec. 4"))
    return [f"<p>Rover <b>{title}</b>: {mass:g} kg on {wheels} wheels, static wheel load "
            f"{mass * gravity / wheels:.1f} N (M g / N, the soil's gravity). Source: {source}.</p>",
            table(pd.DataFrame(rows))]


def fig3_section(results: Path) -> list[str]:
    return ["<h2>Fig. 3: Fx against slip (numpy reference wheel)</h2>",
            image(fig3_file(results, "png"), f"Fx(slip) for loads 100-800 N, {soil_label(results)}")]


def identification_section(identification: Path, paper_soil: bool = True) -> list[str]:
    """Table 1 and the identified model; the paper's Fit beside ours only on the paper's soil."""
    sections = ["<h2>Identification (Sec. 3): Table 1</h2>"]
    models = identification / "fit_models.csv"
    if not models.exists():
        return [*sections, missing(models)]
    fits = pd.read_csv(models)
    columns = {"load [N]": fits["load_N"]}
    if paper_soil:
        columns["paper Fit [%]"] = fits["paper_fit_percent"]
    columns.update({"ours, linear Eq. (14) [%]": fits["fit_percent_linear"],
                    "ours, quadratic (recommended) [%]": fits["fit_percent_quadratic"]})
    shown = pd.DataFrame(columns)
    if not paper_soil:
        sections.append("<p>Fit (Eq. 15) of the models identified on this soil; the paper's Table 1 is for its "
                        "own soil and is not set beside them.</p>")
    sections.append(table(shown, {"load [N]": "{:.0f}"}, default="{:.1f}"))
    model_file = identification / "model.json"
    if model_file.exists():
        identified = ModelSet.read(model_file)
        recommended = identified.recommended
        coefficients = identified.model().fx_coefficients.tolist()
        rows = [{"term": f"slip^{k}", "p0 [N]": c[0], "p1 [-]": c[1], "p2 [1/N]": c[2]}
                for k, c in enumerate(coefficients)]
        sections += [f"<p>The recommended ({html.escape(str(recommended))}) model, Fx = Σ c<sub>k</sub>(W) "
                     "slip<sup>k</sup> with "
                     "c<sub>k</sub>(W) = p0 + p1 W + p2 W<sup>2</sup> (W in N):</p>",
                     table(pd.DataFrame(rows), default="{:.5g}")]
    for name, caption in (("fig5_fx_vs_slip.png", "Fig. 5: settled Fx against slip over the fitted range, with "
                           "Fx = a(W) slip + b(W)"),
                          ("fig6_a_of_W.png", "Fig. 6: a(W)"), ("fig7_b_of_W.png", "Fig. 7: b(W)"),
                          ("fig_model_coefficients.png", "the recommended model's coefficients c_k(W)"),
                          ("fig8_validation_575N.png", "Fig. 8: identified model against the FMU at 575 N")):
        sections.append(image(identification / name, caption))
    return sections


def lateral_section(identification: Path) -> list[str]:
    """The identified lateral model: Fits off the grid, the forms tried, Ishigami's trends."""
    sections = ["<h2>Lateral force (the paper's future work): Fy(W, β, slip)</h2>",
                ("<p>Ishigami et al. (2007)'s side force of the wheel (lateral shear and sidewall bulldozing), "
                 "identified like Sec. 3 from torque steps on the test bed with its carriage at slip angles "
                 "0-30°. Model: Fy = Σ c<sub>ik</sub>(W) φ<sub>i</sub>(β) slip<sup>k</sup>, "
                 "φ<sub>i</sub> = β/(|β| + β<sub>i</sub>), c<sub>ik</sub> quadratic in W. "
                 "Validation (Eq. 15) at loads and slip angles off the sweep's grid, the track turning "
                 "between +β and -β while the torque steps 5-40 N·m.</p>")]
    fits, forms, trends = (identification / f"lateral_{name}.csv" for name in ("fit_table", "forms", "trends"))
    if not fits.exists():
        return [*sections, missing(fits)]
    shown = pd.read_csv(fits).rename(columns={
        "load_N": "load [N]", "slip_angle_deg": "slip angle [deg]", "fit_percent": "Fit [%]",
        "max_settled_error_N": "largest settled error [N]", "max_settled_error_percent": "largest settled error [%]"})
    sections.append(table(shown, {"load [N]": "{:.0f}", "slip angle [deg]": "{:.1f}"}, default="{:.2f}"))
    if forms.exists():
        tried = pd.read_csv(forms)[["form", "coefficients", "training_rms_N", "min_fit_percent"]]
        sections += ["<p>Forms tried (the first is used):</p>", table(tried.rename(columns={
            "coefficients": "coefficients [-]", "training_rms_N": "RMS on the sweep [N]",
            "min_fit_percent": "lowest Fit [%]"}), {"coefficients [-]": "{:.0f}"}, default="{:.2f}")]
    if trends.exists():
        measured = pd.read_csv(trends).rename(columns={"trend": "Ishigami et al. 2007 report", "holds": "ours",
                                                       "measured": "measured on our sweep"})
        sections += ["<p>The trends Ishigami et al. report from their single-wheel experiments:</p>", table(measured)]
    for name, caption in (("fig_lateral_fy.png", "Fy against slip angle and slip, sweep and model"),
                          ("fig_lateral_coefficients.png", "coefficients c_ik(W) of the lateral model"),
                          ("fig_lateral_validation_575N.png", "lateral validation at 575 N, ±12.5°")):
        sections.append(image(identification / name, caption))
    return sections



def closed_loop_section(simulation: Path, paper_soil: bool = True) -> list[str]:
    """Table 3 and Fig. 10; the paper's RMS beside ours only on the paper's soil."""
    sections = ["<h2>Closed loop (Sec. 4): Table 3 and Fig. 10</h2>"]
    rms_path, cosim_path = simulation / "rms.csv", simulation / "rms_cosim.csv"
    if not (rms_path.exists() and cosim_path.exists()):
        return [*sections, missing(rms_path)]
    ours, cosim = pd.read_csv(rms_path), pd.read_csv(cosim_path)
    wheels = len(ours)
    side = max(1, wheels // 2)
    cosimulated = f"RoverBody + {wheels} Wheel"
    columns: dict[str, Any] = {"limb": [str(i) for i in ours["limb"]]}
    if paper_soil:
        columns["paper RMS [N]"] = [f"{PAPER_RMS[i]:.1f}" if i in PAPER_RMS else f"— (mirror of limb {i - side})"
                                    for i in ours["limb"]]
    columns.update({"ours, Rover.fmu [N]": ours["rms_N"], f"ours, {cosimulated} [N]": cosim["rms_N"]})
    sections.append(table(pd.DataFrame(columns), default="{:.2f}"))
    sections.append(f"<p>RMS(Fx - Fx_des) per limb; limbs {side + 1}-{wheels} mirror 1-{side}"
                    + (" (the paper reports 1-3)." if paper_soil else "; the paper's Table 3 is for its own soil.")
                    + "</p>")
    record_path = simulation / "simulation.json"
    ablation = simulation / "ablation_fixed_load.csv"
    if ablation.exists():
        fixed = read_record(record_path).get("parameters", {}).get("fixed_load_ablation_N") \
            if record_path.exists() else None
        load = f"{fixed:.0f} N" if isinstance(fixed, (int, float)) else "the static wheel load"
        shown = pd.read_csv(ablation).rename(columns={"rms_lut_N": "RMS, per-load look-up tables [N]",
                                                      "rms_fixed_load_N": f"RMS, one model at {load} [N]"})
        shown["limb"] = shown["limb"].astype(str)
        sections += [f"<p>Ablation: the same controller with one model at a fixed {load} (the rover's static "
                     "wheel load) instead of the per-load look-up tables:</p>", table(shown, default="{:.2f}")]
    if record_path.exists() and read_record(record_path).get("model_mismatch"):
        why = html.escape(str(read_record(record_path)["model_mismatch"]))
        sections.insert(1, f"<p class='note'>Run with --allow-model-mismatch: {why}</p>")
    if record_path.exists():
        checks = read_record(record_path).get("checks", {})
        rows = [{"plant": {"monolithic": "Rover.fmu", "cosim": cosimulated}.get(p, p),
                 **{CHECKS[k][0]: v for k, v in values.items() if k in CHECKS}} for p, values in checks.items()]
        formats = {label: fmt for label, fmt in CHECKS.values()}
        sections += ["<p>Velocity and loads (paper: the rover reaches 1.0 m/s, Fig. 10 g; limb 1 unloads and "
                     f"limb {side} (the rear of a side) loads while accelerating, Fig. 10 c):</p>",
                     table(pd.DataFrame(rows), formats)]
    sections += [image(simulation / "fig10_closed_loop.png", "Fig. 10 (a)-(h), Rover.fmu; limbs drawn solid, "
                       "dashed and dotted, so that curves that coincide stay visible"),
                 image(simulation / "fig_tracking.png", "position x against x_t, the force error Fx - Fx_des, and "
                       "the co-simulated plant minus the monolithic one"),
                 image(simulation / "fig10_closed_loop_cosim.png", f"Fig. 10 (a)-(h), {cosimulated}")]
    return sections


def _agreement(path: Path, cosimulated: str) -> list[str]:
    """The monolithic against the co-simulated steerable rover (path_agreement.csv,
    terrain_agreement.csv), where the file exists."""
    if not path.exists():
        return []
    agree = pd.read_csv(path).rename(columns={
        "speed_max_difference_percent": "speed, largest difference [% of target]",
        "load_max_difference_percent": "loads, largest difference [% of static]",
        "path_max_difference_m": "path, largest distance [m]"})
    return [f"<p>Monolithic against co-simulated ({cosimulated}):</p>", table(agree, default="{:.2g}")]


def path_section(simulation: Path) -> list[str]:
    """The steerable rover following the turn and the lane change."""
    sections = ["<h2>Path following: the steerable rover with the identified Fx and Fy models</h2>",
                ("<p>SteerableRover (body in x, y, yaw with heave, pitch, roll; every wheel driven and "
                 "steered). Path tracking at the body gives a force and yaw-moment demand, allocated to the "
                 "wheels by least squares weighted by their loads; per wheel the inverse identified lateral "
                 "model gives the steering angle and the inverse longitudinal model the torque. Turn: 10 m, "
                 "90° of radius 10 m, 10 m at 0.5 m/s; lane change: 3 m over 15 m at 1.0 m/s. Ablation: "
                 "kinematic steering (wheels along the commanded hub velocities, no slip-angle "
                 "compensation).</p>")]
    metrics, agreement = simulation / "path_metrics.csv", simulation / "path_agreement.csv"
    if not metrics.exists():
        return [*sections, missing(metrics)]
    data = pd.read_csv(metrics)
    shown = pd.DataFrame({
        "scenario": data["scenario"].str.replace("_", " "),
        "run": data["run"].map({"inverse": "identified models, SteerableRover.fmu",
                                "cosim": "identified models, co-simulated", "kinematic": "kinematic steering"}),
        "cross-track RMS [mm]": 1000 * data["cross_track_rms_m"],
        "cross-track max [mm]": 1000 * data["cross_track_max_m"],
        "speed error max [%]": data["speed_error_max_percent"],
        "RMS(Fx - Fx_des), worst wheel [N]": data.filter(like="rms_Fx").max(axis=1),
        "RMS(Fy - Fy_des), worst wheel [N]": data.filter(like="rms_Fy").max(axis=1)})
    sections += ["<p>Floors of the issue: cross-track RMS &lt; 100 mm, max &lt; 300 mm, speed within 5 %, "
                 "force errors &lt; 2 N per wheel (every wheel's value in <code>path_metrics.csv</code>).</p>",
                 table(shown, default="{:.2f}")]
    sections += _agreement(agreement, "SteerableRoverBody + 6 Wheel")
    sections += [image(simulation / "path_xy.png", "paths in the plane and cross-track error; the co-simulated "
                       "run is dashed over the monolithic one (they coincide)"),
                 image(simulation / "path_wheels_turn.png", "turn: wheel forces, slip angles, steering, loads"),
                 image(simulation / "path_wheels_lane_change.png", "lane change: wheel forces, slip angles, loads")]
    return sections


def _run_name(scenario: str, run: str) -> str:
    """How the terrain table names run ``run`` of ``scenario``."""
    if scenario == "soil_crossing":
        return {"inverse": "soil map believed, SteerableRover.fmu", "cosim": "soil map believed, co-simulated",
                "unaware": "paper soil's models everywhere (ablation)"}[run]
    return {"inverse": "compensated, SteerableRover.fmu", "cosim": "compensated, co-simulated",
            "kinematic": "kinematic steering (ablation)", "unaware": "identified models, map unknown (ablation)"}[run]


def terrain_section(simulation: Path) -> list[str]:
    """The steerable rover across side slopes, past a crater and from one soil onto another, with and
    without the controller's knowledge of them."""
    sections = ["<h2>Terrain: side slopes, a crater and a soil crossing</h2>",
                ("<p>The steerable rover drives straight along x across a side slope (the valley to its right) "
                 "at 0.3 m/s on the paper's soil, started rolling on the path. Gravity's component down the "
                 "slope, M g sin(slope), pulls the body downhill; only the wheels' lateral forces hold it "
                 "(Ishigami et al. 2007). <b>Compensated</b>: the path controller adds the downhill pull to "
                 "its force demand as a feed-forward and, through the identified lateral model, steers each "
                 "wheel to the slip angle that gives its share. <b>Kinematic steering</b> (the ablation): the "
                 "wheels point along the commanded hub velocities and the pull is left to the cross-track "
                 "feedback, which yaws the body uphill until the slip angles hold it, at a steady offset. "
                 "Goal of the issue: cross-track RMS within 100 mm at 20° with the identified models.</p>"),
                ("<p><b>Crater</b>: 20 m along x at 1.0 m/s on level ground past a bowl 0.12 m deep of radius "
                 "4 m centred 2.5 m to the right of the path, a height map given hub by hub by a ground "
                 "participant (height, its rate, the local gradients). Compensated: the controller adds the "
                 "pull of the measured loads on the map's slopes under the hubs as a feed-forward; the "
                 "ablation knows only the plane, and the bowl pulls it towards its centre.</p>"),
                ("<p><b>Soil crossing</b>: the 10° side-slope traverse (7 m at 0.3 m/s) from the paper's soil "
                 "onto one softer in shear, HIT-LSS1 of the soil library (cohesion 0.25 kPa against 0.80, friction "
                 "angle 31.9° against 37.2°: less lateral force at a slip angle) beyond a boundary across the "
                 "path at x = 2.5 m. A soil participant gives each wheel the share of the second soil under it "
                 "(the wheel's parameters blend from one soil to the other over 0.5 m). The controller identifies "
                 "the second soil's models for the run (the sweeps on SingleWheel.fmu at the rover's loads) and, "
                 "believing the soil map, uses under each wheel the models of the soil there; the ablation "
                 "keeps the paper soil's models everywhere (the slope still compensated), so it under-steers "
                 "on that soil and the rover drifts downhill until the cross-track feedback holds it (going "
                 "downhill, its motors then do less work per metre).</p>")]
    metrics, agreement = simulation / "terrain_metrics.csv", simulation / "terrain_agreement.csv"
    if not metrics.exists():
        return [*sections, missing(metrics)]
    data = pd.read_csv(metrics)

    def per_wheel(name: str, scale: float = 1.0) -> pd.Series:
        columns = data.filter(regex=f"^mean_{name}_[1-6]_")
        return columns.min(axis=1).map(lambda v: f"{scale * v:.3g}") + " to " + columns.max(axis=1).map(
            lambda v: f"{scale * v:.3g}")

    shown = pd.DataFrame({
        "scenario": data["scenario"].map(lambda s: "crater (height map)" if s == "crater" else
                                         "soil crossing, 10° side slope" if s == "soil_crossing" else
                                         f"side slope {s.rsplit('_', 1)[-1]}°"),
        "run": [_run_name(s, r) for s, r in zip(data["scenario"], data["run"])],
        "cross-track RMS [mm]": 1000 * data["cross_track_rms_m"],
        "cross-track max [mm]": 1000 * data["cross_track_max_m"],
        "heading error max [mrad]": 1000 * data["heading_error_max_rad"],
        "slip [-]": per_wheel("slip"), "slip angle [°]": per_wheel("slipAngle", 180 / math.pi),
        "sinkage [mm]": per_wheel("sinkage", 1000.0), "load [N]": per_wheel("Fz"),
        "energy [J/m]": data["energy_per_metre_J_m"]})
    sections += ["<p>Per wheel: the range over the six wheels of their means over the run's second half "
                 "(uphill wheels 1-3 carry less, downhill 4-6 more). Energy: the motors' work "
                 "&int;&Sigma;&tau;<sub>i</sub>&omega;<sub>i</sub> dt per metre of path.</p>",
                 table(shown, default="{:.3g}")]
    sections += _agreement(agreement, "SteerableRoverBody, given the same ground, + 6 Wheel")
    sections += [image(simulation / "terrain_xy.png", "paths over the ground's height contours and cross-track "
                       "error, compensated and kinematic"),
                 image(simulation / "terrain_wheels_slope_traverse_20.png",
                       "20° side slope: slip, slip angle, sinkage, load, lateral force per wheel"),
                 image(simulation / "terrain_wheels_crater.png",
                       "crater: slip, slip angle, sinkage, load, lateral force per wheel"),
                 image(simulation / "terrain_wheels_soil_crossing.png",
                       "soil crossing: slip, slip angle, sinkage, load, lateral force per wheel, the soil map "
                       "believed and not")]
    return sections


def coupling_section(results: Path) -> list[str]:
    study = results / "cosim_study" / "coupling_error.csv"
    if not study.exists():
        return ["<h2>Co-simulation coupling error</h2>",
                "<p>Not run here (<code>make cosim-study</code> writes it).</p>"]
    data = pd.read_csv(study)
    shown = pd.DataFrame({"master": data["algorithm"], "step [ms]": 1000 * data["step_s"],
                          "largest velocity error [mm/s]": 1000 * data["max_abs_v_error_m_s"],
                          "largest load error [N]": data["max_abs_Fz_error_N"],
                          "wall time [s]": data["cosim_wall_s"]})
    return ["<h2>Co-simulation coupling error</h2>",
            "<p>RoverBody + 6 Wheel against Rover.fmu run by the same master at the same step, 6 s open loop.</p>",
            table(shown, {"step [ms]": "{:.0f}"}, default="{:.3g}"),
            image(results / "cosim_study" / "coupling_error.png", "co-simulated against monolithic rover")]


def montecarlo_section(montecarlo: Path) -> list[str]:
    """Monte Carlo over soil uncertainty (shown only when results/montecarlo exists): the share of
    runs meeting the paper's 1 N, quantiles, the sensitivity ranking and the figures."""
    summary_path = montecarlo / "summary.json"
    if not summary_path.exists():
        return []
    summary = read_record(summary_path)
    study = summary.get("parameters", {})
    sections = ["<h2>Monte Carlo over soil uncertainty</h2>",
                f"<p>Study <b>{html.escape(str(study.get('title') or study.get('file')))}</b>: "
                f"{html.escape(str(study.get('runs')))} samples (seed {html.escape(str(study.get('seed')))}); sample 0 "
                f"is the nominal soil the model was identified on ({html.escape(str(study.get('soil')))}); the "
                f"paper's closed loop, {html.escape(str(study.get('stop_time_s')))} s, "
                "with the controller and the identified model unchanged.</p>"]
    rows = []
    for scenario, numbers in summary.get("scenarios", {}).items():
        share = numbers.get("share_meeting_1N_rms_of_completed")
        quantiles = numbers.get("quantiles", {}).get("rms_Fx_max_N", {})
        rows.append({"scenario": scenario, "runs": numbers["runs"], "completed": numbers["completed"],
                     "failed": numbers["failed"], "stuck": numbers["stuck"],
                     "RMS ≤ 1 N on every limb [% of completed]": 100 * share if share is not None else float("nan"),
                     "largest RMS, median [N]": quantiles.get("median"), "largest RMS, 95 % [N]": quantiles.get("p95")})
    sections.append(table(pd.DataFrame(rows), {"runs": "{:.0f}", "completed": "{:.0f}", "failed": "{:.0f}",
                                               "stuck": "{:.0f}"}, default="{:.3g}"))
    ranking_path = montecarlo / "sensitivity.csv"
    ranking = pd.read_csv(ranking_path) if ranking_path.exists() else pd.DataFrame(columns=["output", "rank"])
    ranking = ranking[ranking["output"] == "rms_Fx_max_N"].dropna(subset=["rank"]).sort_values("rank")
    if not len(ranking):
        sections.append("<p>No sensitivity ranking: too few completed runs.</p>")
    else:
        shown = pd.DataFrame({"rank": ranking["rank"].astype(int).astype(str), "parameter": ranking["parameter"],
                              "PRCC [-]": ranking["prcc"], "p-value": ranking["p_value"],
                              "ρ with distance from nominal [-]": ranking["distance_spearman"],
                              "its p-value": ranking["distance_p_value"], "strongest": ranking["strongest"]})
        sections += ["<p>Which parameter matters most for the largest RMS(Fx - Fx_des): partial rank correlation "
                     "coefficients (monotonic effects, correlated inputs allowed) and the rank correlation with "
                     "the parameter's distance from its nominal value (the controller is identified there, so it "
                     "may degrade whichever way the soil departs); ranked by the larger. Every output's ranking "
                     "is in <code>sensitivity.csv</code>.</p>", table(shown, default="{:.3g}")]
    figures = (("fig_distributions.png", "distributions of the outcomes over the sampled soils"),
               ("fig_sensitivity.png", "sensitivity ranking (PRCC)"),
               ("fig_scatter.png", "largest RMS(Fx - Fx_des) against each parameter"))
    sections += [image(montecarlo / name, caption) for name, caption in figures if (montecarlo / name).exists()]
    return sections + adaptation_section(montecarlo, summary)


def adaptation_section(montecarlo: Path, summary: dict) -> list[str]:
    """The adaptive controller against the nominal one over the same samples (when the study ran
    with ``--adapt``): the shares after the calibration, its cost, and both ECDFs."""
    numbers = summary.get("scenarios", {})
    straight, adapted = numbers.get("straight", {}), numbers.get("straight_adapted")
    if adapted is None or "adapted_share_meeting_1N_rms_of_completed" not in straight:
        return []
    since = straight.get("after_calibration_from_s")
    calibration = summary.get("parameters", {}).get("calibration", {})

    def percent(value: float | None) -> float:
        return 100 * value if value is not None else float("nan")

    walls = adapted.get("quantiles", {}).get("adapt_wall_s", {})
    after = f"RMS ≤ 1 N on every limb after {since:g} s [%]"
    rows = [{"controller": "identified on the nominal soil", "completed": straight["completed"],
             after: percent(straight.get("share_meeting_1N_rms_after_calibration_of_completed")),
             "… over the whole run [%]": percent(straight.get("share_meeting_1N_rms_of_completed"))},
            {"controller": "adaptive (soil estimated from telemetry)", "completed": adapted["completed"],
             after: percent(straight["adapted_share_meeting_1N_rms_of_completed"]),
             "… over the whole run [%]": percent(adapted.get("share_meeting_1N_rms_of_completed"))}]
    amplitude, segment = calibration.get("amplitude", float("nan")), calibration.get("segment", float("nan"))
    text = (f"<p>The same samples with the adaptive controller: a calibration of {since:g} s (excitation "
            f"±{amplitude:g} N·m per level of {segment:g} s, "
            f"sinkage sensor: {'yes' if calibration.get('sinkage_sensor') else 'no'}), the soil estimated from the "
            "rover's wheel torques, spins, loads and speed ("
            f"{'a1, a0 and λ tried too' if calibration.get('optional_parameters', True) else 'a1, a0 and λ kept'}), "
            "the controller's model identified again on "
            "SingleWheel.fmu with the estimated soil, then the paper's law. The whole-run share counts the "
            "calibration's own excitation (its cost); the estimate and the sweep took "
            f"{walls.get('median', float('nan')):.2g} s of wall time per run (median).</p>")
    return ["<h3>Adaptation: the rover estimates the soil it is on</h3>", text,
            table(pd.DataFrame(rows), {"completed": "{:.0f}"}, default="{:.1f}"),
            image(montecarlo / "fig_adaptation.png", "largest RMS(Fx - Fx_des), nominal against adaptive controller")]


def scope_section(results: Path) -> list[str]:
    """What the wheel does outside the paper's scenario, with numbers from the results."""
    lines = ["<h2>Behaviour outside the paper's scope</h2>", "<div class='note'><ul>"]
    fig3 = fig3_file(results, "csv")
    if fig3.exists():
        data = pd.read_csv(fig3)
        zero = data[data["slip"].abs() < 1e-12].sort_values("load_N")
        if len(zero):
            parts = [f"{'a pull' if fx > 0 else 'a resistance' if fx < 0 else 'no force'} of {abs(fx):.1f} N at "
                     f"{load:.0f} N" for load, fx in ((float(r["load_N"]), float(r["Fx_N"])) for _, r in
                                                       zero.iloc[[0, -1]].drop_duplicates().iterrows())]
            pulling = [f"{load:.0f}" for load, fx in zip(zero["load_N"], zero["Fx_N"]) if fx > 0]
            if not pulling:
                meaning = "a rolling wheel needs some slip to pull"
            elif len(pulling) == len(zero):
                meaning = ("the wheel pulls already when it rolls without slip (its sinkage gives shear ahead of "
                           "the contact's bottom)")
            else:
                meaning = (f"it pulls at zero slip at {', '.join(pulling)} N and needs some slip to pull at the "
                           "other loads")
            lines.append(f"<li>At zero slip Fx is {' and '.join(parts)} (Fig. 3, {html.escape(soil_label(results))}): "
                         f"{meaning}.</li>")
    lines += ["<li>Standstill: below 1 mm/s the forces blend into a static regime (a wheel at rest with no torque "
              "stays at rest; on a slope a holding torque holds it), where the identified model, made from "
              "rolling runs, does not apply.</li>",
              "<li>Reverse mirrors forward (equal and opposite forces); braking gives negative slip and Fx.</li>",
              "<li>Beyond the sweep: the look-up tables extend linearly beyond 100-800 N and the torques "
              "5-80 N·m; light wheels under large torques spin out (slip near 1) and are left out of the "
              "fits.</li></ul></div>"]
    return lines


def legwheel_section(simulation: Path) -> list[str]:
    """The paper's own plant, the leg-wheel rover (LegWheelRover.fmu): the straight run's Table 3
    beside the spring-damper rover's and the paper's, and the side slope with and without posture
    control (where the run made them: the paper's rover only)."""
    sections = ["<h2>The leg-wheel rover: six joints per limb (paper Fig. 1)</h2>",
                ("<p>The paper's plant is a leg-wheel robot after NASA/JPL's ATHLETE: six limbs of six rotary "
                 "joints (hip yaw; hip, knee and ankle pitch; ankle steer and roll), each a position servo with "
                 "stiffness, damping and a torque limit, a driven wheel at each end "
                 "(<code>LegWheelRover.fmu</code>; the joints' compliance carries the load). "
                 "<b>Straight run</b>: the paper's controller unchanged, the limbs held in the paper's symmetric "
                 "posture (hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity), "
                 "beside the same run on the spring-damper rover (Rover.fmu) and the paper's Table 3. "
                 "<b>Side slope</b>: a 6 m traverse across a 20&deg; side slope at 0.3 m/s, the path follower "
                 "steering through the ankle steer joints; <b>fixed</b>: the paper's posture, the body parallel "
                 "to the slope; <b>posture control</b>: the body levelled (rolled against the slope), raised to "
                 "1.2 m, its centre of gravity moved uphill until the weight's line passes through the "
                 "footprint's centre, and each hub raised or lowered until the six wheels share the load. "
                 "<b>Climb</b>: the same 6 m straight up a 10&deg; slope; posture control pitches the body level "
                 "(nose down against the slope) and carries its centre of gravity uphill with the pitch, so that "
                 "the middle hubs stay under their hips (their wrist cannot tilt the link along the body) and "
                 "the weight's line passes through the footprint's centre.</p>")]
    rms_path, metrics_path = simulation / "legwheel_rms.csv", simulation / "legwheel_metrics.csv"
    if not rms_path.exists() or not metrics_path.exists():
        return [*sections, "<p>Not run: the leg-wheel scenarios are the paper's rover's "
                "(<code>rover-cosim simulate --only legwheel</code>).</p>"]
    rms_table = pd.read_csv(rms_path).rename(columns={
        "rms_legwheel_N": "leg-wheel rover [N]", "rms_legwheel_cosim_N": "leg-wheel, co-simulated [N]",
        "rms_spring_damper_N": "spring-damper rover (Rover.fmu) [N]",
        "rms_paper_N": "paper, Table 3 [N]"})
    metrics = pd.read_csv(metrics_path)
    patch = metrics[metrics["scenario"] == "patch"]
    climb = metrics[metrics["scenario"] == "climb"]
    metrics = metrics[metrics["scenario"] == "slope"]
    shown = pd.DataFrame({
        "run": metrics["run"].map({"fixed": "paper's posture (fixed)", "posture": "posture control"}),
        "load max/min": metrics["load_spread"], "sinkage max - min [mm]": 1000 * metrics["sinkage_spread_m"],
        "cross-track RMS [mm]": 1000 * metrics["cross_track_rms_m"],
        "cross-track max [mm]": 1000 * metrics["cross_track_max_m"],
        "energy [J/m]": metrics["energy_per_metre_J_m"], "roll at the end [°]": metrics["roll_end_deg"],
        "CoG shift uphill [m]": metrics["shift_y_end_m"]})
    sections += ["<h3>Straight run: RMS(F<sub>x</sub> - F<sub>x,des</sub>) per limb</h3>",
                 table(rms_table, {"limb": "{:.0f}"}, default="{:.3f}"),
                 "<h3>20&deg; side slope</h3>",
                 "<p>Load and sinkage spreads: over the six wheels' means in the run's second half.</p>",
                 table(shown, {"load max/min": "{:.3f}"}, default="{:.3g}"),
                 *_climb_table(climb),
                 "<h3>A wheel in a soft patch</h3>",
                 ("<p>The front-left wheel starts in a patch of loose dust (ours: the paper's soil with a tenth of "
                  "its pressure-sinkage moduli, a quarter of its cohesion, 30&deg; friction: it sinks about 115 mm "
                  "against 24 mm) and the rover creeps 0.8 m at 0.1 m/s. <b>Rolls through</b>: posture control, "
                  "the wheel drags out of the patch. <b>Steps out</b>: the posture controller lifts the wheel that "
                  "sank past 60 mm (in the air it carries no load, makes no force, its motor held at 0), carries "
                  "it 1.0 m ahead onto firm soil and sets it down, the five others holding the body.</p>"),
                 table(pd.DataFrame({
                     "run": patch["run"].map({"roll": "rolls through", "step": "steps the wheel out"}),
                     "distance [m]": patch["distance_m"], "mean speed [m/s]": patch["mean_speed_m_s"],
                     "energy [J/m]": patch["energy_per_metre_J_m"],
                     "front-left sinkage max [mm]": 1000 * patch["sinkage_1_max_m"],
                     "in the patch [s]": patch["in_patch_s"]}), default="{:.3g}"),
                 image(simulation / "legwheel_stance.png", "the stances: the paper's posture and the posture "
                       "control's on the side slope and on the climb (side, front and top views)"),
                 image(simulation / "legwheel_limbs_slope.png", "side slope, per limb: joint torques, load, "
                       "sinkage, slip (solid: fixed posture; dashed: posture control)"),
                 image(simulation / "legwheel_limbs_climb.png", "climb, per limb: joint torques, load, "
                       "sinkage, slip (solid: fixed posture; dashed: posture control)"),
                 image(simulation / "legwheel_limbs_patch.png", "soft patch, per limb: joint torques, load, "
                       "sinkage, slip (solid: rolls through; dashed: steps the wheel out)"),
                 image(simulation / "legwheel_limbs_straight.png", "straight run, per limb: joint torques, load, "
                       "sinkage, slip")]
    return sections


def _climb_table(climb: pd.DataFrame) -> list[str]:
    """The climb's rows of legwheel_metrics.csv as a table (none: a run from before the climb)."""
    if climb.empty or "pitch_end_deg" not in climb.columns:
        return []
    return ["<h3>10&deg; climb</h3>",
            table(pd.DataFrame({
                "run": climb["run"].map({"fixed": "paper's posture (fixed)", "posture": "posture control"}),
                "load max/min": climb["load_spread"], "sinkage max - min [mm]": 1000 * climb["sinkage_spread_m"],
                "mean speed [m/s]": climb["mean_speed_m_s"], "energy [J/m]": climb["energy_per_metre_J_m"],
                "pitch at the end [°]": climb["pitch_end_deg"], "CoG shift uphill [m]": climb["shift_x_end_m"]}),
                {"load max/min": "{:.3f}"}, default="{:.3g}")]


def effects_section(simulation: Path) -> list[str]:
    """Grousers, slip-sinkage and multi-pass ruts (issue 48): Table 1 and Table 3 with each switched on,
    with the smooth wheel's model and with the model identified with the effect; per wheel its sinkage;
    the trends."""
    sections = ["<h2>Wheel effects: grousers, slip-sinkage, multi-pass ruts</h2>",
                ("<p>The paper's identification (Table 1) and straight run on Rover.fmu (Table 3) with one effect "
                 "switched on at a time on the chosen wheel and soil made smooth, each with the controller's model "
                 "given to <code>simulate</code> (identified on the chosen wheel and soil: for the paper's, the "
                 "smooth wheel; what the effect costs an unaware model) and with the variant's own model, identified "
                 "again on SingleWheel.fmu with the effect on (the identification plan for that wheel and soil). "
                 "<b>Grousers</b>: the soil sheared at the grouser tips and on the trapped soil's "
                 "sides (Ding et al. 2011; the wheel's own grousers, else 10 mm &times; 24, illustrative). "
                 "<b>Slip-sinkage</b>: the sinkage exponent n + n<sub>slip</sub>|s| (Ding et al. 2011; the soil's "
                 "own n<sub>slip</sub>, else 1.0: lugged wheels sank 3&ndash;7 times their static sinkage at 60 % "
                 "slip in Ding et al. 2010's tests, which n<sub>slip</sub> 0.8&ndash;2 gives on the paper's soil; see "
                 "the "
                 "figure). <b>Multi-pass</b>: a rut participant gives the "
                 "middle and rear wheels the rut the wheel ahead left; the soil under its floor carried that "
                 "pressure (Wong's repetitive loading, rigid reload); a single-wheel test bed runs one pass, so "
                 "it has no model of its own. Cruise: t &ge; 10 s.</p>")]
    path = simulation / "effects_ablation.csv"
    if not path.exists():
        return [*sections, "<p>Not run (<code>rover-cosim simulate --only effects</code>).</p>"]
    names = {"smooth": "smooth wheel", "grousers": "grousers", "slip_sinkage": "slip-sinkage",
             "multi_pass": "multi-pass"}
    models = {"given_model": "given (--model)", "own_model": "identified for the variant",
              "smooth_model": "given (--model)"}  # the last: files written before "given_model"
    fits_path = simulation / "effects_table1.csv"
    if fits_path.exists():
        fits = pd.read_csv(fits_path)
        rows = [{"variant": names.get(str(variant), str(variant)), "model": label,
                 **{f"Fit {load:g} N [%]": fit for load, fit in zip(group["load_N"], group[f"fit_percent_{model}"])}}
                for variant, group in fits.groupby("variant", sort=False) for model, label in models.items()
                if f"fit_percent_{model}" in group]
        sections += ["<p>Table 1 on each variant's test bed (Eq. 15 on the validation staircase).</p>",
                     table(pd.DataFrame(rows), default="{:.1f}")]
    ablation = pd.read_csv(path)
    if "model" not in ablation:  # written before the re-identification
        ablation = ablation.assign(model="given_model")
    wheels = sorted(ablation["wheel"].unique())
    half = wheels[: max(1, len(wheels) // 2)]  # one side: the other mirrors it on the straight run
    rows = []
    for (variant, model), group in ablation.groupby(["variant", "model"], sort=False):
        group = group.set_index("wheel")
        rows.append({"variant": names.get(str(variant), str(variant)), "model": models.get(str(model), str(model)),
                     **{f"sinkage {i} [mm]": 1000 * group.loc[i, "sinkage_mean_m"] for i in half},
                     **{f"RMS {i} [N]": group.loc[i, "rms_N"] for i in half}})
    sections += [f"<p>Table 3 with each effect: wheels {', '.join(map(str, half))} (one side; the other mirrors "
                 "it).</p>",
                 table(pd.DataFrame(rows), default="{:.3g}")]
    turn_path = simulation / "effects_path_sinkage.csv"
    if turn_path.exists():
        turn = pd.read_csv(turn_path)
        turn = turn[turn["wheel"].isin(half) | turn["wheel"].isin([w + len(half) for w in half])]
        sections += ["<p>The path following's turn (90&deg; left, radius 10 m, SteerableRover.fmu) without and with "
                     "ruts: mean sinkage per wheel on the first straight and on the arc, where the rear wheels leave "
                     "the front wheels' tracks in part (wheels 1&ndash;3 left, 4&ndash;6 right, front to rear).</p>",
                     table(turn.assign(**{"sinkage, virgin soil [mm]": 1000 * turn["sinkage_virgin_m"],
                                          "sinkage, ruts [mm]": 1000 * turn["sinkage_ruts_m"],
                                          "rut under the wheel [mm]": 1000 * turn["rut_depth_m"]})
                           [["phase", "wheel", "sinkage, virgin soil [mm]", "sinkage, ruts [mm]",
                             "rut under the wheel [mm]"]], default="{:.3g}")]
    sections += [image(simulation / "effects_trends.png", "the models' trends: drawbar pull at 20 % slip against "
                       "grouser height and count, sinkage against slip with slip-sinkage")]
    return sections


def provenance_section(results: Path) -> list[str]:
    records = [fig3_file(results, "json"), results / "identification" / "identification.json",
               results / "simulation" / "simulation.json", results / "simulation" / "path_following.json",
               results / "simulation" / "terrain.json"]
    if (results / "simulation" / "legwheel.json").exists():  # the paper's rover only
        records.append(results / "simulation" / "legwheel.json")
    if (results / "simulation" / "effects.json").exists():
        records.append(results / "simulation" / "effects.json")
    if (results / "montecarlo" / "summary.json").exists():  # an optional study: listed only when run
        records.append(results / "montecarlo" / "summary.json")
    return ["<h2>Provenance</h2>", *(provenance(path) for path in records)]

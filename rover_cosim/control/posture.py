"""The leg-wheel rover's posture controller (issue 47), an orchestrator block: the 36 joint
set-points of LegWheelRover / LegWheelRoverBody from a posture of the body over its six hubs.

The posture: the hubs' footprint on the ground (x_i, y_i in the heading frame, the paper's
x = 1.5, 0, -1.5 m, y = ±1.5 m by default), the centre of gravity at ``height`` [m] above it and
``shift`` [m] to the left of the footprint's centre, the body turned by roll and pitch against the
ground plane; every ankle link along the ground's normal, each wheel rolling along its heading.
The joints are :func:`rover_cosim.limbs.stance_inverse`'s for it (numpy), the steering the path
follower asks for turns the ankle steer joints (about the ankle link: a heading change of ``δ``
is ``-δ`` on the joint).

With ``control`` the block closes its slow loops every ``period`` [s] (0.1 s; the inverse kinematics
is Newton on a tilted body, warm-started from the last posture):

1. height: ``height_cmd`` integrates the error of the measured height ``z`` (ground frame) so
   that the body stands at ``height`` (default: the posture's) however much the limbs give under
   the load (it starts at the posture's own: a run starts on the limbs as they are,
   ``limbs.static_heave`` below it); a levelled body on a side slope stands higher than the
   paper's posture so that the uphill middle limb does not fold shut (at 1.0 m and 20 deg its knee
   is at 170 deg);
2. roll: the roll command integrates the error of the measured roll against the level roll
   (the ground's slope seen from the body's heading: on a side slope of θ with the valley to the
   right, roll = -θ levels the body), so that the body ends level however the limbs give;
3. pitch: the pitch command integrates the error of the measured pitch against the level pitch
   (on a slope of θ along the heading, uphill ahead, pitch = -θ levels the body), and the centre
   of gravity moves along the ground with it, ``shift_x`` = -height tan(pitch): so the middle
   limbs' hubs stay under their hips in the body frame. Those limbs, steered 90 deg in the
   paper's posture, have their ankle roll axis along the pitch axes (a wrist singularity): they
   cannot tilt their links along the body, and their hub moves fore and aft only by the hip yaw,
   whose lever is the 0.125 m from the hip to the hub (a hub 10 mm off would take a 5 deg yaw,
   and a few mm more the hip yaw and the steer trade places). The same rule is the load balance
   along the heading: a level body's middle hubs are under its centre of gravity, so the weight's
   line of action passes through the middle hubs (the lifts keep zero mean, so the middle hubs'
   mean stays put);
4. load balance: the lateral shift of the centre of gravity integrates the lateral offset of the
   loads' centre from the footprint's centre (Σ y_i W_i / Σ W_i), so that the weight's line of
   action passes through the footprint's centre; along the heading the centre of gravity is the
   pitch's (3.), so there the corner hubs (front and rear) move fore and aft together until the
   footprint's centre is the loads' (on a climb the contacts lie r sin θ uphill of the hubs and the
   pull acts at the ground: the loads' centre falls behind the middle hubs);
5. load sharing: six limbs carry the body with more contacts than it needs, so how the load
   spreads among them is the limbs' to choose: each hub's ``lift`` integrates its load's excess
   over the mean (over a nominal limb stiffness), the lifts kept at zero mean (the height loop
   owns the mean), until every wheel carries the same load and, on one soil, sinks alike. Without
   it a stiffer limb (the downhill middle one, stretched) carries most. (A lift pattern along a
   plane tilts the body, which the attitude loops tilt back; the shift loops take the plane's
   part of the loads away first, so the two do not drift against each other.)

With ``step_over`` (``StepOver``) it also steps a stuck wheel out: a wheel that sinks past the
trigger has its hub lifted (the wheel leaves the ground: no load, no force; the block passes the
path follower's torques through and holds that wheel's at 0), carried ahead and set down, the
other five carrying the body; each limb once, one at a time.

A posture out of the limbs' reach (a steep climb's level pitch, with the corner hubs moved back,
can ask the rear limbs for more than their 2 m) is not commanded: that update is undone and the
block holds the last posture the limbs reach (``report()["held_unreachable_s"]``: when).

Every command moves at a bounded rate (``rate_*``), so a posture is reached smoothly from where
the run starts, and the set-points move linearly from one update's joints to the next over the
period (a first-order hold: a step of a few millimetres at a hub would load a stiff limb with
hundreds of newtons at once); the block declares them ``ramped_outputs``, so that under
``gauss-seidel-interpolated`` the FMU takes each step's set-points as the line they move on, not
held at the step's end value (a joint servo fed a staircase of 1 ms steps makes the FMU's
integrator reject and re-linearise: on the soft patch 2.5x the FMU's time). The ramps' slopes are outputs
too (``hipYawRate[i]`` ...: over each step the slope of the ramp that ends there), for the FMU's
inputs of the same names: the hubs move against the body at J q_set', and the wheels roll or slide
over that (a corner hub carried ahead by the balance loop, a stepping hub set down). The shipped
scenarios (``jobs.legwheel``) do not connect them yet: the loops were tuned on hub motion the
wheels did not see (see the leg-wheel design page, "Not yet"). Without ``control``
the block holds the posture it was made with (the paper's by default) and only steers.

What runs every step (the hold, the steering, the torques through) has a C twin
(``posture_block.c``) for the native stepper, bit for bit the block's; the slow loops stay
Python's: every ``period`` the twin calls back into the block's update (the inverse kinematics,
about 15 ms an update at 10 Hz), which leaves the block's state (its report, its history) as a
run stepped in Python would.
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.limbs import JOINTS, LimbGeometry, Unreachable, athlete_limbs, stance_inverse
from rover_cosim.orchestrator import native as native_code
from rover_cosim.orchestrator.native import doubles

#: The block's C twin (what runs every step; the slow loops call back into Python), for the native stepper.
C_SOURCE = Path(__file__).with_name("posture_block.c")
#: posture_block.c's PostureUpdate: (now [s], the inputs) -> 0 on success.
_UPDATE = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double))

#: The joints' variable names in the leg-wheel FMUs, in a limb's joint order.
JOINT_INPUTS = ("hipYaw", "hipPitch", "kneePitch", "anklePitch", "ankleSteer", "ankleRoll")
#: The paper's footprint: hubs 1-3 front, middle, rear on the left, 4-6 on the right (x, y) [m].
PAPER_FOOTPRINT = ((1.5, 1.5), (0.0, 1.5), (-1.5, 1.5), (1.5, -1.5), (0.0, -1.5), (-1.5, -1.5))
PAPER_HEIGHT = 1.0  # m, the centre of gravity above the hubs (RoverParameters.hCoG)


@dataclass(frozen=True)
class Posture:
    """The body over its hubs: ``height`` [m] of the centre of gravity above the hubs, its ``shift``
    (x, y) [m] from the footprint's centre, ``roll`` and ``pitch`` [rad] against the ground plane,
    and each hub's ``lift`` [m] above that plane (0: every hub on it; a hub set higher presses its
    wheel less hard into the ground, the others harder)."""

    height: float = PAPER_HEIGHT
    shift: tuple[float, float] = (0.0, 0.0)
    roll: float = 0.0
    pitch: float = 0.0
    lift: tuple[float, ...] = ()

    def hubs(self, footprint: Sequence[tuple[float, float]]) -> np.ndarray:
        """The hubs relative to the centre of gravity in the ground's heading frame [m]."""
        lift = self.lift or (0.0,) * len(footprint)
        return np.array([[x - self.shift[0], y - self.shift[1], -self.height + dz]
                         for (x, y), dz in zip(footprint, lift)])


@dataclass
class PostureGains:
    """The loops' integral gains and the commands' rate limits (SI)."""

    height: float = 2.0          # 1/s: height command per metre of height error, per second
    attitude: float = 2.0        # 1/s: roll (pitch) command per radian of roll (pitch) error, per second
    balance: float = 1.0         # 1/s: shift per metre of the loads' offset, per second
    sharing: float = 2.0         # 1/s: lift per metre of load excess (over sharing_stiffness), per second
    sharing_stiffness: float = 2.6e4  # N/m: the nominal limb stiffness the load excess is divided by
    rate_lift: float = 0.02      # m/s
    rate_height: float = 0.05    # m/s
    rate_attitude: float = math.radians(3.0)  # rad/s
    rate_shift: float = 0.15     # m/s
    max_shift: float = 0.6       # m

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError(f"posture gains: {name} = {value!r}: expected a finite value >= 0")


@dataclass(frozen=True)
class StepOver:
    """Step a stuck wheel out: when a wheel sinks deeper than ``trigger_sinkage`` [m], its hub is
    raised by ``lift`` [m] over ``lift_time`` [s] (the wheel leaves the ground: no load, no force; its
    motor's torque is held at 0), carried ``reach`` [m] ahead over ``swing_time`` [s] and set down
    over ``lower_time`` [s]; each limb steps once."""

    trigger_sinkage: float = 0.06
    lift: float = 0.25
    reach: float = 1.0
    lift_time: float = 0.5
    swing_time: float = 1.0
    lower_time: float = 0.5

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"step over: {name} = {value!r}: expected a finite value > 0")

    def profile(self, elapsed: float) -> tuple[float, float, bool]:
        """(lift [m], the share of ``reach`` covered [1], done) ``elapsed`` [s] into the step."""
        up, across = self.lift_time, self.lift_time + self.swing_time
        if elapsed < up:
            return self.lift * elapsed / up, 0.0, False
        if elapsed < across:
            return self.lift, (elapsed - up) / self.swing_time, False
        down = (elapsed - across) / self.lower_time
        return self.lift * max(0.0, 1.0 - down), 1.0, down >= 1.0


@dataclass
class _Step:
    """A step under way: the limb (0-based), when it began [s], its footprint x [m] and lift [m] then."""

    limb: int
    began: float
    x0: float
    lift0: float


@dataclass
class _Loops:
    """The controller's state: the commanded posture and the joints that realise it."""

    height: float
    shift: np.ndarray
    roll: float
    pitch: float
    lift: np.ndarray
    joints: np.ndarray
    previous: np.ndarray  # the joints of the update before: the outputs move from these to ``joints``
    footprint: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # the hubs' (x, y) [m], per limb
    step: _Step | None = None
    stepped: list[tuple[int, float, float]] = field(default_factory=list)  # (limb 1-based, began, ended) [s]
    next_update: float = 0.0
    history: list[tuple[float, ...]] = field(default_factory=list)
    held: list[float] = field(default_factory=list)  # the updates [s] whose posture the limbs could not reach


class PostureController:
    """Orchestrator block: inputs ``z``, ``roll``, ``pitch``, ``yaw`` (m, rad), the loads
    ``W[1..6]`` (N) and the steering ``steer[1..6]`` (rad) the path follower asks for; outputs the 36
    joint set-points (``hipYaw[i]`` ... ``ankleRoll[i]``, rad), the commanded posture
    (``height_cmd``, ``shift_x``, ``shift_y`` in m, ``roll_cmd``, ``pitch_cmd`` in rad) and the set-points'
    rates (``hipYawRate[i]`` ... ``ankleRollRate[i]``, rad/s: the FMU moves the hubs against the body at
    J q_set' with them). See the module docstring."""

    def __init__(self, name: str, *, posture: Posture = Posture(), control: bool = False,
                 slope: float = 0.0, downhill: float = 0.0, height: float | None = None,
                 limbs: Sequence[LimbGeometry] | None = None,
                 footprint: Sequence[tuple[float, float]] = PAPER_FOOTPRINT, period: float = 0.1,
                 gains: PostureGains | None = None, step_over: StepOver | None = None):
        self.name = name
        self.limbs = tuple(limbs) if limbs is not None else athlete_limbs()
        if len(footprint) != len(self.limbs):
            raise ValueError(f"block {name!r}: footprint of {len(footprint)} hubs for {len(self.limbs)} limbs")
        self.height = posture.height if height is None else height
        for key, value in (("period", period), ("posture height", posture.height), ("height", self.height)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"block {name!r}: {key} = {value!r}: expected a finite value > 0")
        if not (math.isfinite(slope) and 0 <= slope < math.pi / 2):
            raise ValueError(f"block {name!r}: slope = {slope!r} rad: expected [0, pi/2)")
        self.posture, self.control = posture, bool(control)
        self.slope, self.downhill = float(slope), float(downhill)
        self.footprint = tuple((float(x), float(y)) for x, y in footprint)
        # the corner limbs: not mounted within 15 deg of straight out sideways (the middle ones, whose
        # hubs stay under their hips: see the module docstring)
        self.corner = np.array([abs(math.cos(limb.mount_yaw)) > math.sin(math.radians(15.0)) for limb in self.limbs])
        self.corner_x = float(np.mean([x for (x, _), corner in zip(self.footprint, self.corner) if corner]))
        self.period = float(period)
        self.gains = gains or PostureGains()
        self.step_over = step_over
        if step_over is not None and not self.control:
            raise ValueError(f"block {name!r}: step_over needs control = True (the steps are made at its updates)")
        n = len(self.limbs)
        stepping = step_over is not None  # the sinkages in, the torques through (a lifted wheel's held at 0)
        self.inputs = ("z", "roll", "pitch", "yaw", *[f"W[{i}]" for i in range(1, n + 1)],
                       *[f"steer[{i}]" for i in range(1, n + 1)],
                       *([f"sinkage[{i}]" for i in range(1, n + 1)] + [f"tau_cmd[{i}]" for i in range(1, n + 1)]
                         if stepping else []))
        self.outputs = (*[f"{joint}[{i}]" for joint in JOINT_INPUTS for i in range(1, n + 1)],
                        "height_cmd", "shift_x", "shift_y", "roll_cmd", "pitch_cmd",
                        *([f"tau[{i}]" for i in range(1, n + 1)] if stepping else []),
                        *[f"{joint}Rate[{i}]" for joint in JOINT_INPUTS for i in range(1, n + 1)])
        self.units = {"z": "m", "roll": "rad", "pitch": "rad", "yaw": "rad", "height_cmd": "m", "shift_x": "m",
                      "shift_y": "m", "roll_cmd": "rad", "pitch_cmd": "rad",
                      **{f"W[{i}]": "N" for i in range(1, n + 1)}, **{f"steer[{i}]": "rad" for i in range(1, n + 1)},
                      **{f"{joint}[{i}]": "rad" for joint in JOINT_INPUTS for i in range(1, n + 1)},
                      **{f"{joint}Rate[{i}]": "rad/s" for joint in JOINT_INPUTS for i in range(1, n + 1)},
                      **{f"sinkage[{i}]": "m" for i in range(1, n + 1)},
                      **{f"{name}[{i}]": "N.m" for name in ("tau_cmd", "tau") for i in range(1, n + 1)}}
        self.units = {k: v for k, v in self.units.items() if k in self.inputs or k in self.outputs}
        #: the set-points move linearly over each step (gauss-seidel-interpolated ramps them in the FMU)
        self.ramped_outputs = self.outputs[:JOINTS * n]
        self.feedthrough = True
        self.loops = self._initial()
        #: the last inputs and outputs (the C twin starts from them)
        self._last: tuple[np.ndarray, np.ndarray] = (np.zeros(len(self.inputs)), np.zeros(len(self.outputs)))

    # --- the posture ----------------------------------------------------------------------------
    def joints_of(self, posture: Posture, start: np.ndarray | None = None,
                  footprint: np.ndarray | None = None) -> np.ndarray:
        """The joints (a row of six per limb) of ``posture`` over ``footprint`` (default: the
        block's), the wheels straight ahead."""
        pose = np.array([0.0, 0.0, 0.0, posture.roll, posture.pitch, 0.0])
        feet = [tuple(row) for row in (footprint if footprint is not None else np.array(self.footprint))]
        return stance_inverse(self.limbs, posture.hubs(feet), pose, 0.0, start)

    def _initial(self) -> _Loops:
        """The loops at the start: the posture the block was made with (a run starts from it)."""
        lift = np.array(self.posture.lift or (0.0,) * len(self.limbs), float)
        joints = self.joints_of(self.posture)
        return _Loops(self.posture.height, np.array(self.posture.shift, float), self.posture.roll,
                      self.posture.pitch, lift, joints, joints.copy(), np.array(self.footprint, float))

    def level_attitude(self, yaw: float) -> tuple[float, float]:
        """(roll, pitch) [rad] against the ground plane that level the body at heading ``yaw`` [rad]."""
        slope_tan = math.tan(self.slope)
        along, lateral = math.cos(self.downhill - yaw), math.sin(self.downhill - yaw)
        return math.atan(slope_tan * lateral), math.atan(slope_tan * along)

    def _update(self, t: float, u: np.ndarray) -> None:
        """The slow loops, every ``period`` (see the module docstring); a posture the limbs cannot
        reach is not commanded: the update is undone and the last reachable posture held."""
        loops = self.loops
        # what _move changes before it can fail (its history entry comes after the joints)
        before = (loops.height, loops.shift.copy(), loops.roll, loops.pitch, loops.lift.copy(), loops.footprint.copy(),
                  dataclasses.replace(loops.step) if loops.step else None, len(loops.stepped))
        try:
            self._move(t, u)
        except Unreachable:
            (loops.height, loops.shift, loops.roll, loops.pitch, loops.lift, loops.footprint, loops.step,
             stepped) = before
            del loops.stepped[stepped:]
            loops.previous = loops.joints
            loops.held.append(t)

    def _move(self, t: float, u: np.ndarray) -> None:
        """One update of the loops and the joints that realise them (Unreachable: out of the limbs' reach)."""
        loops, gains, dt = self.loops, self.gains, self.period
        n = len(self.limbs)
        z, roll, pitch, yaw = float(u[0]), float(u[1]), float(u[2]), float(u[3])
        loads = np.asarray(u[4:4 + n], float)
        roll_level, pitch_level = self.level_attitude(yaw)
        loops.height = _toward(loops.height, loops.height + gains.height * (self.height - z) * dt,
                               gains.rate_height * dt)
        loops.roll = _toward(loops.roll, loops.roll + gains.attitude * (roll_level - roll) * dt,
                             gains.rate_attitude * dt)
        loops.pitch = _toward(loops.pitch, loops.pitch + gains.attitude * (pitch_level - pitch) * dt,
                              gains.rate_attitude * dt)
        loops.shift[0] = -loops.height * math.tan(loops.pitch)  # the middle hubs under their hips (3.)
        total = float(loads.sum())
        if total > 0:
            foot = loops.footprint
            offset = (foot - foot.mean(axis=0)).T @ loads / total  # the loads' centre from the footprint's (x, y)
            wanted = float(np.clip(loops.shift[1] - gains.balance * offset[1] * dt, -gains.max_shift, gains.max_shift))
            loops.shift[1] = _toward(float(loops.shift[1]), wanted, gains.rate_shift * dt)
            if loops.step is None:  # along the heading: the corner hubs move (4.), not while a limb steps
                reach = float(foot[self.corner, 0].mean()) - self.corner_x
                wanted = float(np.clip(reach + gains.balance * offset[0] * dt, -gains.max_shift, gains.max_shift))
                foot[self.corner, 0] += _toward(reach, wanted, gains.rate_shift * dt) - reach
            carrying = np.ones(n, bool)
            if loops.step is not None:
                carrying[loops.step.limb] = False  # the stepping limb carries nothing and shares nothing
            excess = np.where(carrying, loads - loads[carrying].mean(), 0.0) / gains.sharing_stiffness
            wanted_lift = loops.lift + gains.sharing * excess * dt
            wanted_lift[carrying] -= wanted_lift[carrying].mean() - loops.lift[carrying].mean()
            change = np.clip(wanted_lift - loops.lift, -gains.rate_lift * dt, gains.rate_lift * dt)
            loops.lift = loops.lift + np.where(carrying, change, 0.0)
        if self.step_over is not None:
            self._step(t, np.asarray(u[4 + 2 * n:4 + 3 * n], float))
        posture = Posture(loops.height, (float(loops.shift[0]), float(loops.shift[1])), loops.roll, loops.pitch,
                          tuple(float(v) for v in loops.lift))
        loops.previous = loops.joints
        loops.joints = self.joints_of(posture, loops.joints, loops.footprint)
        loops.history.append((t, loops.height, float(loops.shift[0]), float(loops.shift[1]), loops.roll,
                              loops.pitch, *loops.lift.tolist()))

    def _step(self, t: float, sinkages: np.ndarray) -> None:
        """The step-over manoeuvre (``StepOver``) at the update at ``t`` [s]: begin one for the
        deepest wheel past the trigger (one limb at a time, each once), or move the one under way."""
        loops, plan = self.loops, self.step_over
        assert plan is not None
        if loops.step is None:
            done = {limb - 1 for limb, _, _ in loops.stepped}
            deep = [i for i in np.argsort(-sinkages) if sinkages[i] > plan.trigger_sinkage and i not in done]
            if not deep:
                return
            i = int(deep[0])
            loops.step = _Step(i, t, float(loops.footprint[i, 0]), float(loops.lift[i]))
        step = loops.step
        lift, covered, finished = plan.profile(t - step.began)
        loops.lift[step.limb] = step.lift0 + lift
        loops.footprint[step.limb, 0] = step.x0 + plan.reach * covered
        if finished:
            loops.stepped.append((step.limb + 1, step.began, t))
            loops.step = None

    def _rates(self) -> np.ndarray:
        """The set-points' rates [rad/s] (a row per limb): the slope of the ramp from the last
        update's joints to the new ones (the steering's changes not counted)."""
        return (self.loops.joints - self.loops.previous) / self.period

    def _outputs(self, u: np.ndarray, now: float, rates: np.ndarray) -> np.ndarray:
        """The set-points at ``now`` [s]: moving linearly from the last update's joints to the new
        ones over a period (a step of a few millimetres at a hub would load a stiff limb with
        hundreds of newtons at once), the steering added; ``rates`` their slopes (see :meth:`step`)."""
        n, loops = len(self.limbs), self.loops
        fraction = min(max((now - (loops.next_update - self.period)) / self.period, 0.0), 1.0)
        joints = loops.previous + fraction * (loops.joints - loops.previous)
        joints[:, 4] -= np.asarray(u[4 + n:4 + 2 * n], float)  # a heading change of d is -d on the steer joint
        commands = [loops.height, loops.shift[0], loops.shift[1], loops.roll, loops.pitch]
        if self.step_over is None:
            return np.concatenate([joints.T.reshape(-1), commands, rates.T.reshape(-1)])
        torques = np.asarray(u[4 + 3 * n:4 + 4 * n], float).copy()
        if loops.step is not None:
            torques[loops.step.limb] = 0.0  # a wheel in the air is not driven
        return np.concatenate([joints.T.reshape(-1), commands, torques, rates.T.reshape(-1)])

    # --- the block interface --------------------------------------------------------------------
    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        self.loops = self._initial()
        self.loops.next_update = t0 + self.period
        self._last = (np.array(u0, float), self._outputs(u0, t0, self._rates()))
        return self._last[1]

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """The outputs at t + h; the rates are the slopes over the step that ends there (taken
        before an update at t + h starts the next ramp), as the set-points' ramp over the step is."""
        now = t + h
        rates = self._rates()
        if self.control and now >= self.loops.next_update - 1e-12:
            self._update(now, u)
            self.loops.next_update += self.period
        outputs = self._outputs(u, now, rates)
        self._last = (u, outputs)
        return outputs

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (posture_block.c) from its state now, for the native stepper; None
        where it cannot be compiled (the block then steps in Python). The twin calls back into this
        block's update every ``period``, so that the block's state follows the run."""
        library = native_code.load_library(C_SOURCE)
        if isinstance(library, str):
            return None
        n, n_inputs = len(self.limbs), len(self.inputs)
        shared = np.zeros(2 * n * JOINTS + 6)
        self._share(shared)
        made: list[int] = []

        def update(now: float, inputs: Any) -> int:
            try:
                u = np.ctypeslib.as_array(inputs, shape=(n_inputs,)).copy()
                self._update(now, u)
                self.loops.next_update += self.period
                self._share(shared)
                return 0
            except BaseException as error:  # noqa: BLE001 - reported through the twin's message
                text = f"the posture update at t = {now:.6g} s failed: {type(error).__name__}: {error}"
                library.posture_fail(made[0], text.encode(errors="replace"))
                return 1

        callback = _UPDATE(update)
        pointer = ctypes.c_void_p
        library.posture_new.restype = pointer
        library.posture_new.argtypes = [ctypes.c_int] * 3 + [ctypes.c_double] * 2 + [pointer, _UPDATE, pointer,
                                                                                      pointer]
        library.posture_fail.argtypes = [pointer, ctypes.c_char_p]
        inputs, outputs = self._last
        component = library.posture_new(n, int(self.step_over is not None), int(self.control), self.period,
                                        self.loops.next_update, shared.ctypes.data, callback, doubles(inputs),
                                        doubles(outputs))
        if not component:
            raise MemoryError(f"block {self.name!r}: its C twin could not be made (out of memory)")
        made.append(component)
        return native_code.NativeBlock(library, component, "posture", keep=(shared, callback))

    def _share(self, shared: np.ndarray) -> None:
        """The state the C twin reads (posture_block.c): the joints of the update before and of the
        last one (a row per limb), the commands and the lifted limb (-1: none)."""
        loops, size = self.loops, self.loops.joints.size
        shared[:size] = loops.previous.reshape(-1)
        shared[size:2 * size] = loops.joints.reshape(-1)
        shared[2 * size:2 * size + 5] = (loops.height, loops.shift[0], loops.shift[1], loops.roll, loops.pitch)
        shared[2 * size + 5] = loops.step.limb if loops.step is not None else -1

    def get_state(self) -> _Loops:
        loops = self.loops
        return _Loops(loops.height, loops.shift.copy(), loops.roll, loops.pitch, loops.lift.copy(),
                      loops.joints.copy(), loops.previous.copy(), loops.footprint.copy(),
                      dataclasses.replace(loops.step) if loops.step else None, list(loops.stepped),
                      loops.next_update, list(loops.history), list(loops.held))

    def set_state(self, state: _Loops) -> None:
        self.loops = _Loops(state.height, state.shift.copy(), state.roll, state.pitch, state.lift.copy(),
                            state.joints.copy(), state.previous.copy(), state.footprint.copy(),
                            dataclasses.replace(state.step) if state.step else None, list(state.stepped),
                            state.next_update, list(state.history), list(state.held))

    def report(self) -> dict[str, Any]:
        """The commanded posture at the end and how it got there (every ``period``)."""
        loops = self.loops
        return {"control": self.control, "period_s": self.period, "height_cmd_m": loops.height,
                "shift_m": loops.shift.tolist(), "roll_cmd_rad": loops.roll, "pitch_cmd_rad": loops.pitch,
                "lift_m": loops.lift.tolist(), "footprint_m": loops.footprint.tolist(),
                "steps": [{"limb": limb, "began_s": began, "ended_s": ended} for limb, began, ended in loops.stepped],
                "updates": len(loops.history), "held_unreachable_s": list(loops.held)}


def _toward(value: float, target: float, limit: float) -> float:
    """``target``, but at most ``limit`` from ``value``."""
    return value + max(-limit, min(limit, target - value))


def posture_joints(posture: Posture = Posture(), limbs: Sequence[LimbGeometry] | None = None,
                   footprint: Sequence[tuple[float, float]] = PAPER_FOOTPRINT) -> dict[str, float]:
    """The leg-wheel FMUs' 36 set-point inputs (``hipYaw[1]`` ... ``ankleRoll[6]``, rad) of ``posture``."""
    block = PostureController("posture", posture=posture, limbs=limbs, footprint=footprint)
    joints = block.loops.joints
    return {f"{joint}[{i + 1}]": float(joints[i, k]) for k, joint in enumerate(JOINT_INPUTS)
            for i in range(joints.shape[0])}


assert JOINTS == len(JOINT_INPUTS)

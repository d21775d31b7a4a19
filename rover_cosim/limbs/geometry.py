"""The geometry of the ATHLETE-like leg-wheel rover (paper Fig. 1, after NASA/JPL's ATHLETE):
six limbs of six rotary joints each on a hexagonal body, a driven wheel at the end of each limb.

The joints of a limb, from the body out (Wilcox et al., J. Field Robotics 24, 2007, describe six
rotary joints per limb: a hip yaw, pitch joints at the hip, knee and ankle, and two more at the
ankle; which axes those two turn about is our reading, stated here):

1. hip yaw ``q1`` about the body's z axis at the limb's mount;
2. hip pitch ``q2`` about the limb's horizontal axis (positive: the thigh tips down);
3. knee pitch ``q3`` (positive: the shank bends down from the thigh);
4. ankle pitch ``q4`` (positive: the ankle link bends down from the shank);
5. ankle steer ``q5`` about the ankle link (vertical in the driving posture: the wheel's steering);
6. ankle roll ``q6`` about the axis normal to the link and the wheel's axle (the wheel's camber).

The thigh, shank and ankle link lie along the x axis of their joint frames; the wheel hub sits
``hub_offset`` beyond the ankle roll joint along the link, its axle along the final frame's y axis.
Lengths and mounts are ours (ATHLETE publishes the robot's size: a hexagonal frame about 2.75 m
across standing about 2 m high on wheels of about 0.7 m; our wheel is the paper's, r = 0.355 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Joints per limb and limbs of the paper's rover.
JOINTS = 6
LIMBS = 6
#: The joints' names, in the order of a limb's joint vector.
JOINT_NAMES = ("hip_yaw", "hip_pitch", "knee_pitch", "ankle_pitch", "ankle_steer", "ankle_roll")


def _positive(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name}={value!r}: expected a length > 0 m")
    return float(value)


@dataclass(frozen=True)
class LimbGeometry:
    """One limb: where it is mounted on the body and its link lengths (SI).

    Attributes:
        mount: (x, y, z) of the hip yaw joint in the body frame [m] (x forward, y left, z up, origin
            at the centre of gravity).
        mount_yaw: the direction the limb points at ``q1 = 0`` [rad] (from the body's x axis, to the left).
        thigh: hip pitch to knee [m].
        shank: knee to ankle pitch [m].
        ankle: ankle pitch to the ankle steer and roll joints [m].
        hub_offset: ankle roll joint to the wheel hub [m].
    """

    mount: tuple[float, float, float]
    mount_yaw: float
    thigh: float = 1.0
    shank: float = 1.0
    ankle: float = 0.25
    hub_offset: float = 0.15

    def __post_init__(self) -> None:
        if len(self.mount) != 3 or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in self.mount):
            raise ValueError(f"mount={self.mount!r}: expected (x, y, z) [m], finite")
        if not (isinstance(self.mount_yaw, (int, float)) and math.isfinite(self.mount_yaw)):
            raise ValueError(f"mount_yaw={self.mount_yaw!r}: expected a finite angle [rad]")
        object.__setattr__(self, "mount", tuple(float(v) for v in self.mount))
        object.__setattr__(self, "mount_yaw", float(self.mount_yaw))
        for name in ("thigh", "shank", "ankle", "hub_offset"):
            object.__setattr__(self, name, _positive(name, getattr(self, name)))

    @property
    def drop(self) -> float:
        """Ankle pitch joint to the hub along the ankle link [m] (the link hangs vertical when driving)."""
        return self.ankle + self.hub_offset


def athlete_limbs(across: float = 2.75, mount_height: float = 0.0, **lengths: float) -> tuple[LimbGeometry, ...]:
    """The six limbs of the paper's rover at the corners of a hexagonal frame ``across`` [m] wide
    (corner to corner; ATHLETE's is about 2.75 m), each pointing radially out, numbered as the
    rover's wheels: 1-3 front, middle, rear on the left, 4-6 mirroring them on the right.
    ``lengths``: LimbGeometry's link lengths."""
    radius = _positive("across", across) / 2
    left = (math.radians(30.0), math.radians(90.0), math.radians(150.0))
    angles = (*left, *(-a for a in left))
    return tuple(LimbGeometry((radius * math.cos(a), radius * math.sin(a), float(mount_height)), a, **lengths)
                 for a in angles)

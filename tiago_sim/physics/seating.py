"""Whether a plate is seated in its nest: the success judge's pose decomposition and its limits.

Why its own module: every limit is geometry (the plate's size, the nest's clearance, the slope of
its lead-in ramps) and is derived here, so a test can check the derivation without a simulation;
`plate_sensing.check_placement` applies it to the physics' plate pose. Pure numpy; any thread.

"Seated" means resting flat in the pocket: the plate's footprint inside the pocket and its bottom
on the nest floor, each within what contacts let a resting plate stray (`SEATED_EDGE_TOLERANCE`,
`SEATED_HEIGHT_TOLERANCE`). The plate's bottom-centre frame, seen from the nest's site frame, is
split into
- tilt: the angle between the plate's z and the nest's z (the swing of the rotation);
- yaw: the rotation about the nest's z (the twist), so a tilt never reads as yaw nor a yaw as tilt
  (the earlier judge took tilt = total rotation angle - yaw, but the total is about
  sqrt(yaw^2 + tilt^2): at 1 deg of yaw a plate tilted 1.7 deg read as 0.97 deg);
- x, y: the bottom centre in the nest plane (x along the plate's long side); z: its height.

The limits, with L and W the plate's length and width, c the nest's clearance per side, s the
lead-ins' slope (rise per run: 1 for the 45 deg ramps), e_h the height and e_p the edge tolerance:
- An edge that crosses the pocket edge by d sits d * s up a ramp, so the footprint may cross it
  by b = min(e_p, e_h / s) at most: 0.5 mm here, half a millimetre up a ramp.
- The flat footprint turned by psi reaches L/2 cos psi + W/2 |sin psi| from its centre along x
  and W/2 cos psi + L/2 |sin psi| along y. "turned": |psi| up to the yaw at which a centred plate's
  corners reach the pocket's half-size + b (1.8 deg for an SBS plate, c = 1.5 mm). "off along" and
  "off across": |x| and |y| up to what the yaw leaves of c + b (2.0 mm at psi = 0; 1.3 and 0.9 mm
  at 1 deg). A plate turned past its limit fits nowhere: then only the turn is named.
- "raised" / "sunk": |z| up to e_h.
- "tilted": the highest corner of the bottom may stand at most e_h above the lowest. Tilted by
  theta the corners spread sin(theta) times the plate's span across the tilt: W for a tilt about
  the long side, L about the short side, up to sqrt(L^2 + W^2) over a diagonal. The limit is
  asin(e_h / span): 0.67 deg down to 0.37 deg for an SBS plate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from labware_model.labware import LabwareType
from tiago_description import transforms as tf
from tiago_sim.physics.scene import NEST_LEAD_IN_SLOPE

# What contacts let a resting plate stray from lying flat in the pocket, measured on plates settled
# for 2 s (tests/tiago_sim/physics/test_sim_pick_place.py and test_sim_placement_check.py): the
# bottom's corners up to 0.6 mm apart in height and the centre up to 0.27 mm sunk (a plate resting
# alone runs at the long physics step, 20 solver iterations, where box contacts sink further), the
# footprint up to 0.39 mm past the pocket edge (a plate that slid in over a ramp, still creeping).
SEATED_HEIGHT_TOLERANCE = 0.001  # m
SEATED_EDGE_TOLERANCE = 0.0005  # m


@dataclass(frozen=True)
class PoseInNest:
    """A plate's bottom-centre frame in a nest's site frame, split as the module docstring says.

    Metres and radians; `yaw` in (-pi, pi], `tilt` in [0, pi]; `rise` is how far the highest corner
    of the plate's bottom face stands above the lowest, along the nest's z."""

    x: float
    y: float
    z: float
    yaw: float
    tilt: float
    rise: float

    @classmethod
    def of(cls, T_site_bottom: np.ndarray, labware: LabwareType) -> PoseInNest:
        rotation = np.asarray(T_site_bottom)[:3, :3]
        qx, qy, qz, qw = tf.matrix_to_quat(rotation)
        yaw = tf.wrap_angle(2.0 * math.atan2(qz, qw))  # the twist about the nest's z
        tilt = math.acos(float(np.clip(rotation[2, 2], -1.0, 1.0)))  # plate z against nest z
        # bottom corners at (+-L/2, +-W/2, 0) in the plate frame: their nest heights spread by this
        rise = labware.length * abs(rotation[2, 0]) + labware.width * abs(rotation[2, 1])
        x, y, z = (float(v) for v in np.asarray(T_site_bottom)[:3, 3])
        return cls(x, y, z, yaw, tilt, float(rise))


def _turn_reaching(crosswise: float, lengthwise: float, reach: float) -> float:
    """The yaw psi >= 0 at which crosswise * sin(psi) + lengthwise * cos(psi) = reach: where a corner
    of a centred plate (half-size `lengthwise` along the checked direction, `crosswise` across it)
    reaches `reach` (a sum of sine and cosine is radius * sin(psi + phase))."""
    radius = math.hypot(crosswise, lengthwise)
    return math.asin(min(reach / radius, 1.0)) - math.atan2(lengthwise, crosswise)


@dataclass(frozen=True)
class SeatingLimits:
    """The limits of one plate type in one nest (sizes in m); `missed` names those a pose exceeds."""

    length: float
    width: float
    clearance: float
    height_tolerance: float = SEATED_HEIGHT_TOLERANCE
    edge_tolerance: float = SEATED_EDGE_TOLERANCE
    ramp_slope: float = NEST_LEAD_IN_SLOPE

    @classmethod
    def for_nest(cls, labware: LabwareType, clearance: float) -> SeatingLimits:
        return cls(labware.length, labware.width, clearance)

    @property
    def beyond_edge(self) -> float:
        """How far the footprint may cross the pocket edge: the edge tolerance, unless the ramp would
        lift the crossing edge higher than the height tolerance allows."""
        return min(self.edge_tolerance, self.height_tolerance / self.ramp_slope)

    @property
    def turn_limit(self) -> float:
        """Largest |yaw| at which a centred flat plate still fits (the tighter of the two sides)."""
        reach = self.clearance + self.beyond_edge
        across = _turn_reaching(self.length / 2, self.width / 2, self.width / 2 + reach)  # corner reach in y
        along = _turn_reaching(self.width / 2, self.length / 2, self.length / 2 + reach)  # in x
        return min(across, along)

    def along_limit(self, yaw: float) -> float:
        """Largest |x| for a flat plate at this yaw: the clearance the turned footprint leaves."""
        footprint = self.length / 2 * math.cos(yaw) + self.width / 2 * abs(math.sin(yaw))
        return max(self.length / 2 + self.clearance + self.beyond_edge - footprint, 0.0)

    def across_limit(self, yaw: float) -> float:
        """Largest |y| for a flat plate at this yaw."""
        footprint = self.width / 2 * math.cos(yaw) + self.length / 2 * abs(math.sin(yaw))
        return max(self.width / 2 + self.clearance + self.beyond_edge - footprint, 0.0)

    def tilt_limit(self, pose: PoseInNest) -> float:
        """Largest tilt in this pose's tilt direction that keeps the bottom's corners within the
        height tolerance of each other (about the long side when there is no tilt)."""
        span = pose.rise / math.sin(pose.tilt) if pose.tilt > 1e-9 else self.width
        return math.asin(min(self.height_tolerance / span, 1.0))

    def missed(self, pose: PoseInNest) -> list[str]:
        """Every limit `pose` exceeds, in words: "tilted 1.7 deg (limit 0.7)"; empty when seated."""
        fits = abs(pose.yaw) <= self.turn_limit  # past the turn limit no position fits: the turn says it
        checks = [
            ("off along the nest's long side by", abs(pose.x), "mm", self.along_limit(pose.yaw), fits),
            ("off across the nest by", abs(pose.y), "mm", self.across_limit(pose.yaw), fits),
            ("raised" if pose.z > 0 else "sunk", abs(pose.z), "mm", self.height_tolerance, True),
            ("turned", abs(pose.yaw), "deg", self.turn_limit, True),
            ("tilted", pose.tilt, "deg", self.tilt_limit(pose), True),
        ]
        shown = {"mm": lambda metres: 1000.0 * metres, "deg": math.degrees}
        return [
            f"{label} {shown[unit](value):.1f} {unit} (limit {shown[unit](limit):.1f})"
            for label, value, unit, limit, applies in checks
            if applies and value > limit
        ]

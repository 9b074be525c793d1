"""The keywords every walk takes: :func:`sandslope.simulate`, :func:`sandslope.simulate_ensemble`
and :func:`sandslope.check_convergence` share them, as ``sandslope simulate``'s flags. The
extension reads them by the request layer's field table (each left out, or ``None``, takes the
table's default), and a test holds this list to that table
(``_sandslope.walk_keyword_defaults()``)."""

from typing import TypedDict


class WalkSettings(TypedDict, total=False):
    """Keywords of a walk, with their flags (docs/simulate.md, docs/model.md §15-§20)."""

    k_n: float  # --k-n: normal resistance at every slope instead of the terrain's, N/m^3
    k_s: float  # --k-s: shear strength at every slope instead of the terrain's, N/m^3
    dt_s: float  # --dt: time step, s (default T / 2000 pitch locked, T / 16000 pitch free)
    creep_m_s: float  # --creep: creep speed of the contact law at rest, m/s (default 1e-7)
    servo_limit: bool  # False is --no-servo-limit: ignore the robot file's torque limit
    body_pitch: str  # --body-pitch: "locked" (default) or "free"
    rft_scaling: str  # --rft-scaling: "motion" (default), "components" or "li2013"
    leg_friction: float  # --leg-friction: leg-sand friction coefficient, 0 to 10 (§20.1)
    duty_cycle: float  # --duty-cycle: 0.1 to 0.9 (§20.2; default 0.5)
    disturbed_sand: float  # --disturbed-sand: greater than 0, at most 1 (§20.3; default 1)
    one_sided_belly: bool  # --one-sided-belly: the belly pushes only (§20.5; the default)
    two_faced_belly: bool  # --two-faced-belly: the belly a plate in sand on both faces (§20.5)
    actuator: str  # --actuator: "ideal" (default) or "servo", the XL330's motor (§20.6)
    sample_rate_hz: float  # --rate: trajectory sample rate, Hz (default 120)

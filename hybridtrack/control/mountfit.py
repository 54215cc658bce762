"""The mount's errors estimated online, by recursive least squares with forgetting.

Heliostat and trough practice corrects open-loop tracking with a pointing-error model of the
mount fitted from observed sun positions (Stone 1986; Baheti & Scott 1980; Khalsa, Ho &
Andraka 2011). The model here has the pedestal terms, the axis's azimuth and tilt, and each
axis's encoder zero:

* a single-axis collector: ``axis_azimuth_error``, ``axis_tilt_error``, ``encoder_offset``;
* a heliostat: the pedestal's two tilt components (``axis_tilt_error`` about the east-west
  line, ``axis_roll_error`` about the north-south line) and the zero offsets of its azimuth
  and elevation encoders (``encoder_offset_azimuth``, ``encoder_offset``). A pedestal turned
  about the vertical is the same as an azimuth encoder offset, and is reported as one. Its sun
  sensor sits on the mirror and reads across the mirror's face, so its mounting bias across the
  face is the pointing model's collimation term (``collimation_error``, CA): CA / cos(e) of
  azimuth at the target's elevation e (`collimation_secant`, |cos e| held to cos 85° as the
  controller's conversion holds it, `hybridtrack.control.sensing.axis_offset`), nothing of
  elevation. Without it the fit and the clock watch had only a constant azimuth zero for what
  grows through the day as sec(e): the zero took part of it (0.93-0.955° for 0.86°) and the clock
  watch the rest (a clock 160-210 s fast over three sunny days, against -8 to +22 s without a
  bias). The axes' non-orthogonality (NPAE, tan e) and gravity sag of the full model are left out:
  the world has neither.

Each trusted sensor reading gives, per axis, the sun's angle in encoder coordinates. Against
the controller's computed target it is a linear measurement of the parameters through the
target's derivatives, precomputed for every scan (`jacobian`): the model is linearised about
the nominal mount, which costs at most about 0.02° for errors of 1° (second order in the
errors; measured in the tests). The update is RLS with an exponential forgetting factor
(time constant `memory`), its covariance bounded by the prior so it cannot wind up while the
sun is hidden; each step is bounded by clipping the innovation at `clip` standard deviations.

A reading taken in a clear gap between clouds is pulled toward the bright cloud edge near the
sun, and the controller can see how much such light there is. Each reading's variance is the
sensor's noise plus the pull it may carry, σ_pull = `pull_gain` · x / max(sin h, cos 85°)
(`pull_spread`), from the light above the clear sky's level, x, and the computed sun's altitude
h. The derivation follows the world's sensor (`hybridtrack.sensor.read_pointing`): cloud light
in view, P, off the sun by d, moves the centroid by P / (B + P) · d, B the beam. In a clear gap
the beam is the clear sky's, and the photocurrent's excess over what a clear sky gives is the
cloud light on the sensor's diffuse share s_d of the diffuse light, x ≈ s_d · ΔD / B. The
circumsolar part of ΔD that a sun-facing sensor sees is F1 · ΔD / max(cos z, cos 85°) (Perez
et al. 1990), of which the view holds a share v, so P / B ≈ (F1 · v / s_d) · x / sin h. With
F1 ≈ 0.3 (Perez's circumsolar brightening under broken cloud), v = 0.8, s_d = 0.5 and d the 2–6°
of a cloud edge (rms per axis about 2.8°), the gain is F1 · v / s_d · 2.8° ≈ 1.4°. The level is
a running mean of the ratio over the last hour of fit readings (`MountEstimator.excess_light`),
since the controller's clear-sky model misses a given day's clear sky by a few percent. A bound
on the step in the fit's own metric, Δθᵀ P⁻¹ Δθ ≤ c², is already implied by the innovation
clip: an RLS step has Δθᵀ P⁻¹ Δθ = ν² · hᵀPh / s ≤ ν² with ν the normalised innovation, so a
bound with c at `clip` never binds; a larger variance shrinks the step in every direction.

A parameter the sun's path does not excite is not fitted to noise. Every `check_every`
updates the information matrix (forgotten like the covariance) is inspected: while its
condition number exceeds `MAX_CONDITION`, the pedestal (axis) terms are frozen and only the
encoder zeros learn. An east-west trough at an equinox, whose sun path moves its target as a
tilt would, is the textbook case (a test shows it frozen).

While frozen, the pedestal terms are Schmidt "consider" parameters: they are never moved, so the
filter's covariance keeps the prior's 2° on them, although the readings taken meanwhile tell
much more (on the clear day before Nanjing's 2013-09-23, a Fresnel row, the information form's
1σ is 0.13° and 0.16° when the pedestal is released). A filter released from its own covariance
would throw that away and let the next few readings set the pedestal. So the fit carries the information vector too (Σ row ·
residual / r, forgotten like the matrix), and at a release it restarts from the batch solution
of everything it has seen, θ = (Λ + I/σ₀²)⁻¹ b with P = (Λ + I/σ₀²)⁻¹, σ₀ the prior's 1σ: the
information form of the same least-squares problem.

References
----------
Baheti, R. S. & Scott, P. F. (1980). Design of self-calibrating controllers for heliostats in a
solar power plant. *IEEE Transactions on Automatic Control* 25(6), 1091-1097.
doi:10.1109/TAC.1980.1102521

Stone, K. W. (1986). *Automatic heliostat track alignment method*. US Patent 4,564,275.

Khalsa, S. S. S., Ho, C. K. & Andraka, C. E. (2011). An automated method to correct heliostat
tracking errors. SolarPACES 2011, Granada. SAND2011-6233C.

Wallace, P. T. *TPOINT: a telescope pointing analysis system* (manual), "The pointing terms": the
altazimuth collimation error CA, a left-right shift constant on the sky, CA·sec(elevation) in azimuth.

Ljung, L. & Söderström, T. (1983). *Theory and Practice of Recursive Identification*. MIT Press.

Perez, R., Ineichen, P., Seals, R., Michalsky, J. & Stewart, R. (1990). Modeling daylight
availability and irradiance components from direct and global irradiance. *Solar Energy* 44(5),
271-289. doi:10.1016/0038-092X(90)90055-H
"""

from __future__ import annotations

import math

import numpy as np

from .. import mountpass
from ..collectors import checked_vectors
from ..errors import HybridtrackError
from ..mounting import pointing_vectors, rotate
from .sensing import COSINE_FLOOR

__all__ = ["MountEstimator", "jacobian", "pull_spread", "spd_inverse", "ordered_dot", "ordered_matmul",
           "parameter_names", "MAX_CONDITION", "ROTATION_STEP", "LEVEL_READINGS", "LIGHT_TOLERANCE", "HORIZON"]

#: Above this condition number of the information matrix, axis azimuth and tilt are frozen.
MAX_CONDITION = 1e3
#: Degrees: the central-difference step of the mount rotation's derivative (a 3 × 3 matrix,
#: smooth in its angles: the difference errs by about 1e-12 at this step).
ROTATION_STEP = 1e-4
#: Fit readings over which the clear-sky light level is averaged (an hour at one every five minutes).
LEVEL_READINGS = 12
#: How far a clear sky's light ratio wanders about its level within an hour, not counted as excess.
LIGHT_TOLERANCE = 0.01
#: cos 85°: Perez's bound on the zenith's cosine (circumsolar light stops growing below 5° of sun).
HORIZON = math.cos(math.radians(85.0))


def parameter_names(collector) -> list[str]:
    """The fitted parameters: the two pedestal (axis) terms, then one encoder zero per axis."""
    if collector.single_axis:
        return ["axis_azimuth_error", "axis_tilt_error", "encoder_offset"]
    return ["axis_tilt_error", "axis_roll_error", "encoder_offset_azimuth", "encoder_offset", "collimation_error"]


def collimation_secant(elevation):
    """1 / cos(elevation), |cos| held to cos 85° (`hybridtrack.control.sensing.COSINE_FLOOR`): the
    azimuth degrees a heliostat's sensor collimation error of one degree across the mirror's face
    takes at that elevation of the target (degrees), as the controller converts its sensor's
    readings (`hybridtrack.control.sensing.axis_offset`)."""
    from .sensing import COSINE_FLOOR

    cosine = np.cos(np.radians(np.asarray(elevation, float)))
    return 1.0 / np.where(cosine < 0.0, np.minimum(cosine, -COSINE_FLOOR), np.maximum(cosine, COSINE_FLOOR))


def vector_collimation_secant(vectors) -> np.ndarray:
    """`collimation_secant` at the elevation of each pointing vector (``(..., 3)``, unit, z up):
    what the plan's targets and the fit's derivatives both take of the collimation error."""
    return collimation_secant(np.degrees(np.arcsin(np.clip(np.asarray(vectors, float)[..., 2], -1.0, 1.0))))


def jacobian(altitude, azimuth, collector) -> np.ndarray:
    """d(target)/d(parameter) per scan, (N, axes, parameters): the pedestal terms by the chain
    rule through the mount's rotation about the nominal mount (`vector_jacobian`), each encoder
    zero exactly 1 on its own axis."""
    return vector_jacobian(pointing_vectors(altitude, azimuth, collector, night=True), collector)


def vector_jacobian(vectors: np.ndarray, collector, *, lit: np.ndarray | None = None,
                    engine: str = "auto") -> np.ndarray:
    """`jacobian` from the collector's pointing vectors (`hybridtrack.mounting.pointing_vectors`,
    with ``night=True``), when the caller has them already.

    A pedestal term turns the vectors the mount sees by a rotation whose derivative at the
    nominal mount is a constant 3 × 3 matrix (central differences of `mounting_rotation` over
    1e-4°, exact to about 1e-12); the chain rule through the angle's own gradient
    (`_angle_gradient`) gives the target's derivative at every scan without turning the
    geometry four times.

    `lit`: the scans where the computed target exists (the plan's), zero elsewhere, as it comes
    out there anyway (no target, no derivative); a year's nights are half its scans. `engine`:
    ``numpy`` the reference path; ``compiled`` (where numba is installed) one compiled pass
    (`hybridtrack.mountpass.derivatives`), the same bits (`tests/test_mountpass.py`); ``auto``
    compiled where it can be. A `lit` of another length or type is refused by name.
    """
    mountpass.check_engine(engine, "vector_jacobian")
    vectors = checked_vectors(vectors, "vector_jacobian", "vectors")
    if vectors.ndim != 2:
        raise HybridtrackError(f"vector_jacobian: vectors must be a path of (east, north, up) vectors, shape "
                               f"(N, 3); got shape {vectors.shape}")
    if lit is not None and (np.shape(lit) != vectors.shape[:1] or np.asarray(lit).dtype != np.bool_):
        raise HybridtrackError(f"vector_jacobian: lit must be one True or False a scan, shape ({len(vectors)},); got "
                               f"{np.asarray(lit).dtype} of shape {np.shape(lit)}")
    turns = _rotation_derivatives(collector)
    if engine != "numpy":
        b = np.radians(collector.axis)
        fast = mountpass.derivatives(vectors, np.ones(len(vectors), bool) if lit is None else lit, turns,
                                     collector.kind == "heliostat", np.cos(b), np.sin(b),
                                     (0.5 if collector.kind == "fresnel" else 1.0) * np.degrees(1.0),
                                     np.degrees(1.0), COSINE_FLOOR)
        if fast is not None:
            return fast
    if lit is not None:
        derivatives = vector_jacobian(vectors[lit], collector, engine="numpy")
        out = np.zeros((len(lit), *derivatives.shape[1:]))
        out[lit] = derivatives
        return out
    axes = 1 if collector.single_axis else 2
    gradient = _angle_gradient(vectors, collector)  # (N, axes, 3)
    out = np.zeros((len(vectors), axes, len(parameter_names(collector))))
    for k, turn in enumerate(turns):
        turned = rotate(vectors, turn)  # d(vectors as the mount sees)/d(parameter)
        # summed in this order, not einsum's own (by the machine's SIMD width: (0 + 2) + 1 here);
        # at the zenith a heliostat's infinite azimuth gradient meets a zero component: NaN, which
        # nan_to_num below makes 0, as the compiled pass does, without a RuntimeWarning to the user
        with np.errstate(invalid="ignore"):
            out[:, :, k] = gradient[..., 0] * turned[:, None, 0] + gradient[..., 1] * turned[:, None, 1] \
                + gradient[..., 2] * turned[:, None, 2]
    for a in range(axes):
        out[:, a, 2 + a] = 1.0
    if axes == 2:  # the sensor's collimation error: an angle across the face is sec(e) of azimuth
        out[:, 0, 4] = vector_collimation_secant(vectors)
    return np.nan_to_num(out, copy=False)  # in place: a heliostat-year's copy took 0.03 s


def _rotation_derivatives(collector) -> np.ndarray:
    """d(rotation)/d(parameter) at the nominal mount for the two pedestal terms, (2, 3, 3):
    central differences of `mounting_rotation` over `ROTATION_STEP`."""
    from .plan import MountEstimate

    names, h = parameter_names(collector), ROTATION_STEP
    turns = []
    for name in names[:2]:
        up, down = (MountEstimate.from_parameters(names, [sign * h if n == name else 0.0 for n in names])
                    .rotation(collector) for sign in (1.0, -1.0))
        turns.append((up - down) / (2.0 * h))
    return np.array(turns)


def _angle_gradient(vectors: np.ndarray, collector) -> np.ndarray:
    """d(angle)/d(vector) of `hybridtrack.mounting.angles_on_mount` at the nominal mount,
    degrees per unit, (N, axes, 3): a single axis's ``atan2(z, across)`` (half of it for a
    Fresnel mirror, which turns half the sun's angle), a heliostat's ``atan2(x, y)`` azimuth
    and ``asin(z)`` elevation."""
    x, y, z = vectors[:, 0], vectors[:, 1], vectors[:, 2]
    degrees = np.degrees(1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        if collector.kind == "heliostat":
            flat = x * x + y * y
            zero = np.zeros_like(x)
            return degrees * np.stack([np.stack([y / flat, -x / flat, zero], axis=-1),
                                       np.stack([zero, zero, 1.0 / np.sqrt(1.0 - np.clip(z * z, 0.0, 1.0))],
                                                axis=-1)], axis=1)
        b = np.radians(collector.axis)
        across = x * np.cos(b) - y * np.sin(b)
        span = across * across + z * z
        d_across, d_z = -z / span, across / span
        share = 0.5 if collector.kind == "fresnel" else 1.0
        return share * degrees * np.stack([d_across * np.cos(b), -d_across * np.sin(b), d_z], axis=-1)[:, None, :]


def pull_spread(gain: float, excess: float, altitude: float) -> float:
    """Degrees, 1σ: how far cloud light near the sun may pull a sensor reading, from the light
    above the clear sky's level (`excess`, a share of the expected clear-sky light) and the
    computed sun's `altitude` (degrees; NaN counts as the horizon).

    gain · excess / max(sin(altitude), cos 85°): the circumsolar light on a sun-facing plane
    per unit of diffuse light grows as 1/sin(altitude), bounded at 85° from the zenith, as in
    Perez et al. (1990). The module's notes derive it.
    """
    rise = math.sin(math.radians(altitude)) if altitude == altitude else 0.0
    return gain * excess / max(rise, HORIZON)


class MountEstimator:
    """Online estimate of the mount's errors (degrees) with its covariance.

    Parameters
    ----------
    axes : int
    noise : float
        Degrees, 1σ of one sun-angle measurement.
    prior : float
        Degrees, 1σ of the prior on each parameter (the bound of the covariance).
    memory : float
        Minutes: the forgetting factor's time constant.
    clip : float
        Innovations are clipped at this many of their standard deviations, so one reading can
        move the fit only so far.
    check_every : int
        Updates between identifiability checks.
    """

    def __init__(self, axes: int, noise: float, prior: float = 2.0, memory: float = 3 * 1440.0,
                 clip: float = 3.0, check_every: int = 10, parameters: int | None = None):
        self.n = 2 + axes if parameters is None else parameters
        self.theta = np.zeros(self.n)
        self.prior = prior * prior
        self.p = np.eye(self.n) * self.prior
        self.information = np.zeros((self.n, self.n))
        self.evidence = np.zeros(self.n)
        self.r = noise * noise
        self.memory = memory
        self.clip = clip
        self.check_every = check_every
        self.updates = 0
        self.axis_frozen = True
        self.condition = math.inf
        self.level = math.nan

    def excess_light(self, ratio: float) -> float:
        """The light above the clear sky's level at a fit reading, then the level updated.

        `ratio` is the photocurrent above dark over the clear-sky photocurrent the controller
        expects (NaN where it expects none). The level is the ratio's running mean over the last
        `LEVEL_READINGS` fit readings: what a clear sky gives against the controller's clear-sky
        model, which misses the day's turbidity by a few percent. Returns
        max(0, ratio − level − `LIGHT_TOLERANCE`), the level taken before the update (0 for a NaN ratio, which leaves the level as it was). The first
        reading a fit ever takes sets the level (and has no excess).
        """
        if not math.isfinite(ratio):
            return 0.0
        if math.isnan(self.level):
            self.level = ratio
        excess = max(0.0, ratio - self.level - LIGHT_TOLERANCE)
        self.level += (ratio - self.level) / LEVEL_READINGS
        return excess

    def predict(self, row) -> float:
        """The correction the fitted mount makes to a computed target: row · theta."""
        return float(ordered_dot(row, self.theta))

    def forget(self, dt: float) -> None:
        """Let `dt` minutes of forgetting pass: the covariance grows (bounded by the prior)."""
        factor = math.exp(-dt / self.memory)
        p = self.p / factor
        scale = np.sqrt(np.minimum(1.0, self.prior / np.diag(p)))
        self.p = p * np.outer(scale, scale)
        self.information *= factor
        self.evidence *= factor

    def update(self, row, residual: float, variance: float | None = None) -> None:
        """Take one measurement: `residual` = measured angle − computed target, with derivatives `row`
        and the reading's `variance` (deg², the datasheet noise's when not given).

        While the pedestal terms are frozen they are "consider" parameters (the Schmidt-Kalman
        filter): their uncertainty is carried in the gain and covariance of the others, but
        they are not moved.
        """
        row = np.asarray(row, float)
        r = self.r if variance is None else variance
        self.information += np.outer(row, row) / r  # what it tells of every parameter, frozen or not
        self.evidence += row * residual / r
        pr = ordered_dot(self.p, row)
        s = r + float(ordered_dot(row, pr))
        gain = pr / s
        if self.axis_frozen:
            gain[:2] = 0.0
        bound = self.clip * math.sqrt(s)
        innovation = residual - float(ordered_dot(row, self.theta))
        error = max(-bound, min(bound, innovation))
        self.theta = self.theta + gain * error
        a = np.eye(self.n) - np.outer(gain, row)  # Joseph form, right for any gain
        self.p = ordered_matmul(ordered_matmul(a, self.p), a.T) + r * np.outer(gain, gain)
        self.updates += 1
        if self.updates % self.check_every == 0:
            self._check()

    def _check(self) -> None:
        """Freeze the pedestal terms while the information matrix is ill-conditioned; at a release
        restart from the information form's solution (`solve`)."""
        singular = np.linalg.svd(self.information, compute_uv=False)
        self.condition = float(singular[0] / max(singular[-1], 1e-300))
        frozen = self.condition > MAX_CONDITION
        if self.axis_frozen and not frozen:
            self.theta, self.p = self.solve()
        self.axis_frozen = frozen

    def solve(self) -> tuple[np.ndarray, np.ndarray]:
        """The batch least-squares solution of every reading taken (forgotten as the fit forgets)
        with the prior: θ = (Λ + I/σ₀²)⁻¹ b and its covariance (Λ + I/σ₀²)⁻¹ (`spd_inverse`)."""
        p = spd_inverse(self.information + np.eye(self.n) / self.prior)
        theta = np.zeros(self.n)
        for i in range(self.n):
            total = 0.0
            for j in range(self.n):
                total += float(p[i, j]) * float(self.evidence[j])
            theta[i] = total
        return theta, p

    def std(self) -> list[float]:
        """1σ of each parameter, degrees."""
        return np.sqrt(np.clip(np.diag(self.p), 0.0, None)).tolist()


def ordered_dot(a, b) -> np.ndarray:
    """Σₖ a[..., k] · b[k], added in turn from k = 0, each product and each sum rounded on its own.

    For a vector `a` the dot product; for a matrix (or a stack of them) the matrix-vector
    product; `ordered_matmul` the matrix product. BLAS promises neither an order nor whether it
    fuses a multiply with an add, and numpy's and numba's BLAS builds differ. The compiled
    controller (`hybridtrack.kernel.controller`) takes these same steps in scalar loops, so the
    two controllers get the same bits: a difference in the last bit grows over a year of
    closed-loop runs (a move made one scan sooner). It also spares the kernel a BLAS call at
    every scan.
    """
    b = np.asarray(b, float)
    total = a[..., 0] * b[0]
    for k in range(1, b.shape[0]):
        total = total + a[..., k] * b[k]
    return total


def ordered_matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The matrix product a @ b as `ordered_dot` sums it: Σₖ a[i, k] · b[k, j] in turn."""
    return ordered_dot(np.asarray(a, float)[:, None, :], b)


def spd_inverse(a: np.ndarray) -> np.ndarray:
    """The inverse of a symmetric positive-definite matrix through its Cholesky factor L
    (A⁻¹ = L⁻ᵀ L⁻¹), one scalar step at a time in a fixed order: the compiled controller
    (`hybridtrack.kernel.controller.spd_inverse`) takes the same steps and so gets the same bits,
    which LAPACK's two builds (numpy's, numba's) do not promise; a difference in the last bit
    grows over a year of closed-loop runs."""
    n = len(a)
    low = np.zeros((n, n))
    for j in range(n):
        total = float(a[j, j])
        for k in range(j):
            total -= low[j, k] * low[j, k]
        low[j, j] = math.sqrt(total)
        for i in range(j + 1, n):
            total = float(a[i, j])
            for k in range(j):
                total -= low[i, k] * low[j, k]
            low[i, j] = total / low[j, j]
    inverse_low = np.zeros((n, n))
    for i in range(n):
        inverse_low[i, i] = 1.0 / low[i, i]
        for j in range(i):
            total = 0.0
            for k in range(j, i):
                total -= low[i, k] * inverse_low[k, j]
            inverse_low[i, j] = total / low[i, i]
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            total = 0.0
            for k in range(max(i, j), n):
                total += inverse_low[k, i] * inverse_low[k, j]
            out[i, j] = total
    return out

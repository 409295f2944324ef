"""The force-driven Fig. 4 DEM's model shared by the reference scripts of validation/perf
(`scipy_force_driven.py`, `numpy_force_driven.py`): the SS440c pair, the transmission bar's
dashpot and the Burgoyne-Daraio loading curve (Eq. 1, C^1 region II, Johnson-Cook sigma_y*),
written out as shpb's `LoadingCurve::with_form` and `BurgoyneDaraio::loading_force` compute them.
"""

import math

# --- specimen (specimens/ss440c.toml) and apparatus (src/scene.rs) -------------------------
RHO, E, NU, SY = 7800.0, 204e9, 0.28, 1900e6
JC_C, JC_RATE0 = 0.035, 1e-3
R_SPHERE = 6.35e-3 / 2.0
MASS = RHO * 4.0 / 3.0 * math.pi * R_SPHERE**3
M1 = M2 = MASS
E_STAR = 1.0 / (2.0 * (1.0 - NU**2) / E)
R_EFF = 1.0 / (2.0 / R_SPHERE)
SUM_R = 2.0 * R_SPHERE
Z = 8110.0 * 4865.5 * math.pi * 9.525e-3 * 9.525e-3  # AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S

YIELD_ONSET = 1.6
FIT_R = 0.00159
KH = 4.0 / 3.0 * E_STAR * math.sqrt(R_EFF)


def hertz(radius, d):
    return 4.0 / 3.0 * E_STAR * math.sqrt(radius) * d * math.sqrt(d) if d > 0.0 else 0.0


def curve(sy):
    """Coefficients of the loading curve of Eq. 1 at yield stress sy (LoadingCurve::with_form)."""
    k = YIELD_ONSET * math.pi * sy
    dy = 0.25 * R_EFF / (E_STAR * E_STAR) * k * k
    fy = (1.0 / 6.0) * (R_EFF / E_STAR) ** 2 * k**3
    q = E_STAR / sy
    s = R_EFF / FIT_R
    dp = (0.00428 / q + 1.47e-5) * s
    c1 = -6.76 * q**-0.137 + 6.304
    c2 = (-3.99e-6 / q + 1.01e-9) * s * s
    p0 = c1 * sy
    fp = p0 * math.pi * (2.0 * R_EFF * dp + c2)
    if not (dp > dy and fp > 0.0):
        raise RuntimeError("degenerate law (delta_p <= delta_y) not implemented")
    beta = (dy * fp - dp * fy) / (dy * dp * math.log(dp / dy))
    alpha = fy / dy - beta * math.log(dy)
    jump = alpha + beta * (math.log(dy) + 1.0) - 1.5 * fy / dy
    gamma = -jump / (dp - dy)
    return dy, dp, alpha, beta, gamma, p0 * math.pi * 2.0 * R_EFF, p0 * math.pi * c2


def curve_force(c, d):
    dy, dp, alpha, beta, gamma, a3, b3 = c
    if d <= 0.0:
        return 0.0
    if d <= dy:
        return KH * d * math.sqrt(d)
    if d <= dp:
        return d * (alpha + beta * math.log(d)) + gamma * (d - dy) * (dp - d)
    return a3 * d + b3


STATIC = curve(SY)


def loading_force(d, ddot):
    rate = ddot / SUM_R if ddot > 0.0 else 0.0
    if rate > JC_RATE0:
        return curve_force(curve(SY * (1.0 + JC_C * math.log(rate / JC_RATE0))), d)
    return curve_force(STATIC, d)

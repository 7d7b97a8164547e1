"""Independent reference for crr's multi-DOF impacts: Psycharis' planar two-block stack.

Derived here on its own, with sympy, from the geometry of two rectangular blocks (not from crr's
Γ/γ operators): positions of the two centres of mass for each of the four pivot-sign
combinations, T and U, Lagrange's equations with the ground acceleration a_x(t) entering as an
effective gravity -a_x on every body. Integrated with scipy's DOP853 (rtol 1e-13, atol 1e-15),
with events at each angle crossing 0.

Impact maps (Psycharis 1990), from angular momentum about the pivots that persist, computed from
the bodies' velocities (centre velocity and angular velocity of each block), before with the old
pivots and after with the new ones:
- momentum law (crr's `impact = "momentum"`, plastic impact at the new pivot):
  ground impact: upper block about its (joint) pivot, and both blocks about the new ground pivot;
  bed-joint impact: upper block about its new joint pivot, and both blocks about the ground pivot;
- restitution with r (crr's `impact = { restitution = r }`): the momentum that the impulse cannot
  change (ground impact: upper block about its pivot; bed-joint impact: both blocks about the
  ground pivot) is kept, and the impacting joint's rate takes r times its value in the energy norm
  of the impact, psi+ = r sqrt(kappa+/kappa-) psi-, kappa = (M^-1)_kk of this script's own M.

Conventions (crr's): x horizontal, z up, angles right-handed about +y: a positive angle tilts a
block's top towards +x and makes it pivot on its +x edge. `base` is the lower block's angle, `joint`
the upper block's angle relative to the lower one.

Writes data/<case>.csv (t, base, joint, base_rate, joint_rate at every 0.01 s) and
data/<case>_impacts.csv (t, joint, base_rate_before, joint_rate_before, base_rate_after,
joint_rate_after). Run: python reference.py (needs sympy, numpy, scipy: requirements.txt).
"""

import csv
import math
import os

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

G = 9.81
RHO = 2400.0
B1, H1 = 0.3, 0.75  # lower block half-width, half-height (0.6 x 0.6 x 1.5 m)
B2, H2 = 0.2, 0.8  # upper block (0.4 x 0.4 x 1.6 m)
DEPTH1, DEPTH2 = 0.6, 0.4
M1 = RHO * 2 * B1 * 2 * H1 * DEPTH1
M2 = RHO * 2 * B2 * 2 * H2 * DEPTH2
I1 = M1 * (B1**2 + H1**2) / 3.0  # about the centre, axis y
I2 = M2 * (B2**2 + H2**2) / 3.0
OUT_DT = 0.01
RTOL, ATOL = 1e-13, 1e-15


def rot(th, v):
    """Rotation by th about +y in the (x, z) plane: x -> (cos, -sin), z -> (sin, cos)."""
    x, z = v
    return sp.Matrix([x * sp.cos(th) + z * sp.sin(th), -x * sp.sin(th) + z * sp.cos(th)])


def derive():
    t = sp.symbols("t")
    s1, s2, ax = sp.symbols("s1 s2 ax")
    q1, q2 = sp.Function("q1")(t), sp.Function("q2")(t)
    p1 = sp.Matrix([s1 * B1, 0])
    c1 = p1 + rot(q1, sp.Matrix([0, H1]) - p1)
    p2_rest = sp.Matrix([s2 * B2, 2 * H1])
    p2 = p1 + rot(q1, p2_rest - p1)
    c2 = p2 + rot(q1 + q2, sp.Matrix([0, 2 * H1 + H2]) - p2_rest)
    v1, v2 = c1.diff(t), c2.diff(t)
    w1, w2 = q1.diff(t), q1.diff(t) + q2.diff(t)
    T = (M1 * v1.dot(v1) + M2 * v2.dot(v2) + I1 * w1**2 + I2 * w2**2) / 2
    V = M1 * (G * c1[1] + ax * c1[0]) + M2 * (G * c2[1] + ax * c2[0])
    L = T - V
    qs = [q1, q2]
    dq = [q.diff(t) for q in qs]
    ddq = [q.diff(t, 2) for q in qs]
    eqs = [sp.expand(L.diff(d).diff(t) - L.diff(q)) for q, d in zip(qs, dq)]
    Mm = sp.Matrix(2, 2, lambda i, j: eqs[i].coeff(ddq[j]))
    rest = sp.Matrix([eqs[i] - sum(Mm[i, j] * ddq[j] for j in range(2)) for i in range(2)])
    a, b, da, db = sp.symbols("a b da db")
    sub = {dq[0]: da, dq[1]: db}
    sub2 = {q1: a, q2: b}
    f = lambda e: sp.simplify(e.subs(sub).subs(sub2))
    args = (a, b, da, db, s1, s2, ax)
    mass = sp.lambdify(args, Mm.applyfunc(f), "numpy")
    bias = sp.lambdify(args, rest.applyfunc(f), "numpy")
    # Body kinematics for the impact maps: centres, their velocities, pivots.
    kin = [c1, c2, v1, v2, p1, p2]
    kinf = sp.lambdify(args, [k.applyfunc(f) for k in kin], "numpy")
    return mass, bias, kinf


MASS, BIAS, KIN = derive()


def sgn(side):
    return 1.0 if side > 0 else -1.0


def rhs(t, y, sides, ground):
    a, b, da, db = y
    ax = ground(t)
    m = np.array(MASS(a, b, da, db, sides[0], sides[1], ax), dtype=float)
    r = np.array(BIAS(a, b, da, db, sides[0], sides[1], ax), dtype=float).reshape(2)
    acc = np.linalg.solve(m, -r)
    return [da, db, acc[0], acc[1]]


def bodies(y, sides):
    a, b, da, db = y
    c1, c2, v1, v2, p1, p2 = [np.array(k, dtype=float).reshape(2) for k in KIN(a, b, da, db, sides[0], sides[1], 0.0)]
    return c1, c2, v1, v2, p1, p2, da, da + db


def h_about(point, c, v, m, i, w):
    """Angular momentum about +y of one block about `point`: m (r_z v_x - r_x v_z) + I w."""
    r = c - point
    return m * (r[1] * v[0] - r[0] * v[1]) + i * w


def momenta(y, sides, points):
    """(upper block about points[0], both blocks about points[1])."""
    c1, c2, v1, v2, _, _, w1, w2 = bodies(y, sides)
    hu = h_about(points[0], c2, v2, M2, I2, w2)
    hb = h_about(points[1], c1, v1, M1, I1, w1) + h_about(points[1], c2, v2, M2, I2, w2)
    return np.array([hu, hb])


def impact(y, sides, k, law):
    """The rates after an impact of coordinate k (0 base, 1 joint) with `sides` before."""
    new = list(sides)
    new[k] = -sides[k]
    a, b = y[0], y[1]
    # Points: the upper block's pivot and the ground pivot, those of the new chain (the old and
    # new pivots coincide for the persisting joint; for the impacting one the new pivot is used).
    _, _, _, _, p1n, p2n, _, _ = bodies([a, b, 0.0, 0.0], new)
    points = (p2n, p1n)
    before = momenta(y, sides, points)
    # After: momenta are linear in the rates; columns from unit rates.
    cols = [momenta([a, b, 1.0, 0.0], new, points), momenta([a, b, 0.0, 1.0], new, points)]
    A = np.column_stack(cols)
    if law == "momentum":
        return np.linalg.solve(A, before)
    r = law
    # Restitution: keep the momentum the impulse cannot change (k = 0: upper about its pivot,
    # row 0; k = 1: both about the ground pivot, row 1), set the impacting rate in the energy norm.
    keep = 0 if k == 0 else 1
    m_old = np.array(MASS(a, b, 0, 0, sides[0], sides[1], 0.0), dtype=float)
    m_new = np.array(MASS(a, b, 0, 0, new[0], new[1], 0.0), dtype=float)
    kap_old = np.linalg.inv(m_old)[k, k]
    kap_new = np.linalg.inv(m_new)[k, k]
    psi = r * math.sqrt(kap_new / kap_old) * y[2 + k]
    # Unknown: the other rate, from the kept momentum row.
    other = 1 - k
    rates = np.zeros(2)
    rates[k] = psi
    rates[other] = (before[keep] - A[keep, k] * psi) / A[keep, other]
    return rates


def simulate(y0, duration, law, ground):
    sides = [sgn(y0[0]), sgn(y0[1])]
    t, y = 0.0, np.array(y0, dtype=float)
    grid = [round(i * OUT_DT, 10) for i in range(int(round(duration / OUT_DT)) + 1)]
    rows, impacts = [], []
    gi = 0
    while t < duration:
        def ev(k):
            side = sides[k]
            # side·θ falls through 0 at an impact. The small offset keeps a segment that starts at
            # θ = 0 (just after an impact) off its root: a joint that rises a little and falls
            # back within the first step must be found at its true crossing, not at the start.
            f = lambda tt, yy, *_: side * yy[k] + 1e-13  # noqa: E731
            f.terminal = True
            f.direction = -1.0
            return f

        events = [ev(0), ev(1)]
        sol = solve_ivp(rhs, (t, duration), y, method="DOP853", rtol=RTOL, atol=ATOL,
                        events=events, dense_output=True, args=(sides, ground))
        t_end = sol.t[-1]
        while gi < len(grid) and grid[gi] <= t_end + 1e-12:
            yy = sol.sol(grid[gi])
            rows.append([grid[gi], *yy])
            gi += 1
        if sol.status == 1:
            k = 0 if len(sol.t_events[0]) > 0 else 1
            te = sol.t_events[k][0]
            ye = sol.y_events[k][0].copy()
            ye[k] = 0.0
            rates = impact(ye, sides, k, law)
            impacts.append([te, k, ye[2], ye[3], rates[0], rates[1]])
            sides[k] = -sides[k]
            y = np.array([ye[0], ye[1], rates[0], rates[1]])
            t = te
            if abs(rates[k]) < 1e-3:
                break  # close to seating (crr seats below 1e-4 rad/s): the comparison stops here
        else:
            t = t_end
    return rows, impacts


def no_ground(t):
    return 0.0


def one_sine(amplitude, period):
    return lambda t: amplitude * math.sin(2 * math.pi * t / period) if 0.0 <= t <= period else 0.0


CASES = {
    # name: (base, joint, duration, law, ground)
    "free_momentum": (0.02, -0.03, 3.0, "momentum", no_ground),
    "free_momentum_b": (-0.015, -0.04, 3.0, "momentum", no_ground),
    "free_restitution": (0.02, -0.03, 3.0, 0.9, no_ground),
    "pulse_momentum": (0.01, 0.02, 3.0, "momentum", one_sine(2.0, 0.6)),
}


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "data")
    os.makedirs(out, exist_ok=True)
    for name, (b0, j0, dur, law, ground) in CASES.items():
        rows, impacts = simulate([b0, j0, 0.0, 0.0], dur, law, ground)
        with open(os.path.join(out, f"{name}.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t", "base", "joint", "base_rate", "joint_rate"])
            for r in rows:
                w.writerow([f"{r[0]:.2f}"] + [f"{x:.15e}" for x in r[1:]])
        with open(os.path.join(out, f"{name}_impacts.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t", "joint", "base_rate_before", "joint_rate_before", "base_rate_after", "joint_rate_after"])
            for r in impacts:
                w.writerow([f"{r[0]:.15e}", ["base", "joint"][r[1]]] + [f"{x:.15e}" for x in r[2:]])
        print(name, len(rows), "samples", len(impacts), "impacts", "last t", rows[-1][0])


if __name__ == "__main__":
    main()

"""Derive, with sympy, the flap equation of a blade on a hub that pitches and yaws, and the hub's reaction.

Groundwork for modelling the blades' cyclic flap (tilt and yaw) modes, which the surrogate does not have yet: it
turns the rotor's once-per-revolution moments by the quasi-static flap lag instead
(:func:`surrogates.model.cyclic_flap_lag`). A rigid blade of mass ``m`` at radius ``R`` on a flap hinge at the
hub centre (spring ``K``), azimuth ``psi = Omega t`` (rotation about the shaft +x, the top blade moving to -y),
flapping by ``beta`` downwind, on a hub turned by ``theta`` (about +y, tilt) and ``psi_z`` (about +z, yaw).
Exact kinematics, Lagrange's equations, linearised in ``beta``, ``theta``, ``psi_z``; prints (per unit ``m R^2``)::

    flap:  beta'' + (K/(m R^2) + Omega^2) beta + theta'' cos psi + psi_z'' sin psi
           - 2 Omega theta' sin psi + 2 Omega psi_z' cos psi = 0
    tilt:  (beta'' + Omega^2 beta) cos psi + (rigid-rotor terms)
    yaw:   (beta'' + Omega^2 beta) sin psi + (rigid-rotor terms)

i.e. the classical gyroscopic flap forcing ``2 Omega q`` (Johnson, *Helicopter Theory*), and no ``Omega^2 theta``
term (the blade's tension carries a tilted disc's centripetal acceleration). For an assumed flap mode ``phi(r)``
with tip coordinate ``q_b`` (generalised mass ``m_f``, rotating stiffness ``k_r``, ``S1 = int m phi r dr``) and
three blades, ``q_b = q_c cos psi_b + q_s sin psi_b`` gives the time-invariant fixed-frame system (rows times
3/2, so that the mass is symmetric)::

    mass:      [theta, q_c] = [psi_z, q_s] = 3/2 S1 ;  [q_c, q_c] = [q_s, q_s] = 3/2 m_f
    gyroscopic (velocity terms, skew): G[q_c, q_s] = 3 m_f Omega ; G[q_c, psi_z] = 3 S1 Omega ;
               G[q_s, theta] = -3 S1 Omega ; and their negatives transposed
    stiffness: [q_c, q_c] = [q_s, q_s] = 3/2 (k_r - m_f Omega^2)

whose forced response at zero frequency in the fixed frame is the quasi-static lag, and whose free modes whirl
at ``omega_f +- Omega`` (the regressive one near the 1st tower mode at rated speed). The aerodynamic flap damping
must see each blade's rotating-frame velocity ``(q_c' + Omega q_s) cos psi_b + (q_s' - Omega q_c) sin psi_b``.

Usage (needs sympy: ``pip install -e '.[tools]'``)::

    python tools/cyclic_flap_equations.py     # ~1 min
"""

from __future__ import annotations

import sympy as sp


def main() -> None:
    t = sp.symbols("t")
    m, r, k, w = sp.symbols("m R K Omega", positive=True)
    beta, theta, psiz = (sp.Function(n)(t) for n in ("beta", "theta", "psi_z"))

    def rot(axis: int, a):
        c, s = sp.cos(a), sp.sin(a)
        if axis == 0:
            return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
        if axis == 1:
            return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])
        return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])

    point = sp.Matrix([r * sp.sin(beta), 0, r * sp.cos(beta)])
    pos = rot(2, psiz) * rot(1, theta) * rot(0, w * t) * point
    vel = pos.diff(t)
    lag = sp.Rational(1, 2) * m * (vel.T * vel)[0] - sp.Rational(1, 2) * k * beta**2
    e = sp.symbols("e")
    syms = sp.symbols("B0 B1 B2 T0 T1 T2 P0 P1 P2")
    b0, b1, b2, t0, t1, t2, p0, p1, p2 = syms

    def linear(q):
        eq = sp.diff(sp.diff(lag, q.diff(t)), t) - sp.diff(lag, q)
        eq = eq.xreplace({beta.diff(t, 2): e * b2, theta.diff(t, 2): e * t2, psiz.diff(t, 2): e * p2})
        eq = eq.xreplace({beta.diff(t): e * b1, theta.diff(t): e * t1, psiz.diff(t): e * p1})
        eq = eq.xreplace({beta: e * b0, theta: e * t0, psiz: e * p0})
        return sp.collect(sp.expand(sp.simplify(sp.diff(eq, e).subs(e, 0) / (m * r**2))), list(syms))

    for name, q in (("flap", beta), ("tilt", theta), ("yaw", psiz)):
        print(f"{name}: {linear(q)} = 0")


if __name__ == "__main__":
    main()

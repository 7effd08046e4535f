"""Why OpenFAST's NREL 5 MW rotor (OC3 Hywind deck, AeroDyn v5) is weaker than the ROSCO/CCBlade Cp-Ct table.

Analysis tool (not imported by the package). It holds

* a steady / quasi-steady BEM with AeroDyn's settings (Prandtl tip + hub loss, tangential induction, no drag in
  the induction, Buhl high-induction, full 3-D kinematics: shaft tilt + platform pitch, precone, mean flap
  deflection from ElastoDyn's mode-1 shape scaled to OoPDefl1 with foreshortening, power-law shear, optional
  Pitt/Peters skew redistribution and AeroDyn's TwrPotent=1 potential flow), static polars from the deck;
* the OpenFAST operating points (aerodynamic thrust = RotThrust - rotor weight along the tilted shaft);
* time-domain quasi-steady BEM of the runs (8 m/s turbulent with the run's polar wind field);
* the AeroDyn-driver results (aerodyn_driver built from the same OpenFAST v5.0.0 commit 2895884d, single
  precision, the run's own AeroDyn file with only UA_Mod / TwrPotent / Skew_Mod / outputs changed), recorded in
  AERODYN_DRIVER below; ``write_driver`` regenerates the driver inputs.

Run:  python tools/rotor_gap_bem.py     (about 3 minutes on one core)
"""
import math
import re
import warnings
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

from fowt_env.io import read_openfast

warnings.filterwarnings('ignore')

DECK = Path('/work/shared/reference/openfast/decks/5MW_Baseline')
RHO = 1.225
B = 3
R_HUB = 1.5
TIP = 63.0


def _polar(path):
    lines = path.read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if 'NumAlf' in ln)
    n = int(lines[i].split()[0])
    rows = []
    k = i + 1
    while len(rows) < n:
        s = lines[k].strip()
        if s and not s.startswith('!'):
            rows.append([float(v) for v in s.split()[:3]])
        k += 1
    a = np.array(rows)
    return np.deg2rad(a[:, 0]), a[:, 1], a[:, 2]


AFNAMES = ['Cylinder1', 'Cylinder2', 'DU40_A17', 'DU35_A17', 'DU30_A17', 'DU25_A17', 'DU21_A17', 'NACA64_A17']
POLARS = [_polar(DECK / 'Airfoils' / f'{n}.dat') for n in AFNAMES]


def blade():
    lines = (DECK / 'NRELOffshrBsline5MW_AeroDyn_blade.dat').read_text().splitlines()
    rows = [[float(v) for v in ln.split()] for ln in lines[6:6 + 19]]
    a = np.array(rows)
    return a[:, 0], np.deg2rad(a[:, 4]), a[:, 5], a[:, 6].astype(int) - 1  # span, twist, chord, afid


SPAN, TWIST, CHORD, AFID = blade()


def flap_modes():
    txt = (DECK / 'NRELOffshrBsline5MW_Blade.dat').read_text()
    c = {}
    for m in ('Fl1', 'Fl2'):
        c[m] = [float(re.search(rf'^\s*(\S+)\s+Bld{m}Sh\({k}\)', txt, re.M).group(1)) for k in range(2, 7)]
    return c


MODES = flap_modes()


def mode_shape(x, name='Fl1'):
    """ElastoDyn polynomial flap mode shape and slope (per unit of x = span/61.5)."""
    c = MODES[name]
    w = sum(ck * x ** (k + 2) for k, ck in enumerate(c))
    dw = sum((k + 2) * ck * x ** (k + 1) for k, ck in enumerate(c))
    return w, dw


def coeffs(afid, alpha):
    cl = np.empty_like(alpha)
    cd = np.empty_like(alpha)
    for j, (al, l, d) in enumerate(POLARS):
        m = afid == j
        if np.any(m):
            x = (alpha[m] + np.pi) % (2 * np.pi) - np.pi
            cl[m] = np.interp(x, al, l)
            cd[m] = np.interp(x, al, d)
    return cl, cd


def solve_bem(Vx, Vy, r, rtip, chord, theta, afid, aidrag=False, tidrag=False, tanind=True, tiploss=True,
              hubloss=True, n_iter=64):
    """Ning's 1-D residual in phi, vectorised bisection on (0, pi/2]. Returns phi, a, ap."""
    sig = B * chord / (2 * np.pi * r)

    def ind(phi):
        sphi, cphi = np.sin(phi), np.cos(phi)
        cl, cd = coeffs(afid, phi - theta)
        cn = cl * cphi + (cd * sphi if aidrag else 0.0)
        ctg = cl * sphi - (cd * cphi if tidrag else 0.0)
        F = np.ones_like(phi)
        if tiploss:
            f = B / 2 * np.maximum(rtip - r, 0) / (r * np.abs(sphi))
            F = F * 2 / np.pi * np.arccos(np.clip(np.exp(-f), 0, 1))
        if hubloss:
            f = B / 2 * np.maximum(r - R_HUB, 0) / (R_HUB * np.abs(sphi))
            F = F * 2 / np.pi * np.arccos(np.clip(np.exp(-f), 0, 1))
        F = np.maximum(F, 1e-6)
        k = sig * cn / (4 * F * sphi * sphi)
        kp = sig * ctg / (4 * F * sphi * cphi)
        a = k / (1 + k)
        hi = k > 2 / 3
        g1 = 2 * F * k - (10 / 9 - F)
        g2 = np.maximum(2 * F * k - F * (4 / 3 - F), 0)
        g3 = 2 * F * k - (25 / 9 - 2 * F)
        small = np.abs(g3) < 1e-6
        a_buhl = np.where(small, 1 - 1 / (2 * np.sqrt(np.maximum(g2, 1e-12))),
                          (g1 - np.sqrt(g2)) / np.where(small, 1, g3))
        a = np.where(hi, a_buhl, a)
        ap = kp / (1 - kp) if tanind else np.zeros_like(kp)
        res = sphi / (1 - a) - Vx / Vy * cphi / (1 + ap)
        return res, a, ap

    lo = np.full_like(Vx, 1e-6)
    hi_ = np.full_like(Vx, np.pi / 2)
    rlo = ind(lo)[0]
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi_)
        rm = ind(mid)[0]
        same = np.sign(rm) == np.sign(rlo)
        lo = np.where(same, mid, lo)
        rlo = np.where(same, rm, rlo)
        hi_ = np.where(same, hi_, mid)
    phi = 0.5 * (lo + hi_)
    _, a, ap = ind(phi)
    return phi, a, ap


def rotor(V, omega, pitch_deg, tilt_deg=5.0, precone_deg=2.5, shear=0.2, hub_ht=90.0, tip_defl=0.0,
          defl_shape='Fl1', foreshorten=True, skew=False, twr_potent=False, aidrag=False, tidrag=False,
          n_az=36, rtip_mode='fixed', ref_ht=90.0, cone_in_bem=True):
    """Azimuth-averaged thrust (N, along the shaft) and torque (N m) of the rotor.

    tilt_deg: total shaft elevation (shaft tilt + platform pitch + tower-top slope), upwind end up.
    precone_deg: upwind cone. tip_defl: mean downwind flap tip deflection (m) with the ElastoDyn mode shape.
    """
    s = SPAN  # along the blade from the root
    L = SPAN[-1]
    x = s / L
    if tip_defl != 0.0:
        if defl_shape == 'Fl1':
            w, dw = mode_shape(x, 'Fl1')
        else:
            w, dw = defl_shape(x)
        w = tip_defl * w / (w[-1])
        slope = tip_defl * dw / (mode_shape(np.array([1.0]), 'Fl1')[0][0] if defl_shape == 'Fl1' else 1.0) / L
        if defl_shape != 'Fl1':
            slope = np.gradient(w, s)
    else:
        w = np.zeros_like(s)
        slope = np.zeros_like(s)
    # along-blade coordinate with axial foreshortening
    if foreshorten and tip_defl != 0.0:
        short = np.concatenate([[0], np.cumsum(0.5 * (slope[1:] ** 2 + slope[:-1] ** 2) / 2 * np.diff(s))])
    else:
        short = np.zeros_like(s)
    kap0 = math.radians(precone_deg)
    # coordinates in the coned frame (radial d, axial e_s downwind): undeflected blade at upwind cone kap0
    rb = R_HUB + s - short  # distance along the coned axis
    rad = rb * math.cos(kap0) + w * math.sin(kap0)  # perpendicular distance from the shaft
    axial = -rb * math.sin(kap0) + w * math.cos(kap0)  # downwind along the shaft from the apex
    kap = kap0 - np.arctan(slope)  # local upwind cone angle of the element
    rtip_fixed = (R_HUB + L) * math.cos(kap0)
    rtip = rtip_fixed if rtip_mode == 'fixed' else rad[-1]
    tau = math.radians(tilt_deg)
    es = np.array([math.cos(tau), 0.0, -math.sin(tau)])
    up = np.array([math.sin(tau), 0.0, math.cos(tau)])
    ey = np.array([0.0, 1.0, 0.0])
    psis = np.arange(n_az) * 2 * np.pi / n_az
    theta = TWIST + math.radians(pitch_deg)
    # build arrays (n_az, n_node)
    P = psis[:, None]
    d = np.cos(P)[..., None] * up + np.sin(P)[..., None] * ey  # radial unit
    t = -np.sin(P)[..., None] * up + np.cos(P)[..., None] * ey  # tangential unit (direction of motion)
    n = np.sin(kap)[None, :, None] * d + np.cos(kap)[None, :, None] * es  # element normal (downwind-ish)
    pos = rad[None, :, None] * d + axial[None, :, None] * es  # from the apex
    z = hub_ht + pos[..., 2]
    Vloc = V * np.maximum(z / ref_ht, 1e-3) ** shear
    wind = np.zeros(pos.shape)
    wind[..., 0] = Vloc
    if twr_potent:
        # AeroDyn TwrPotent=1 (baseline potential flow) about the tower axis, x measured from the tower
        # centreline (apex 5.0191 m upwind of the yaw axis along the shaft), tower diameter by height
        xt = pos[..., 0] - 5.0191 * math.cos(tau)
        yt = pos[..., 1]
        zt = z
        Dt = np.interp(zt, [10.0, 87.6], [6.5, 3.87])
        below = zt < 87.6 + 0.0
        r2 = xt * xt + yt * yt
        u = 1 - (Dt / 2) ** 2 * (xt * xt - yt * yt) / r2 ** 2
        v = -2 * (Dt / 2) ** 2 * xt * yt / r2 ** 2
        wind[..., 0] = np.where(below, Vloc * u, Vloc)
        wind[..., 1] = np.where(below, Vloc * v, 0.0)
    Vx = np.sum(wind * n, axis=-1)
    Vy = omega * rad[None, :] - np.sum(wind * t, axis=-1)
    rr = np.broadcast_to(rad[None, :], Vx.shape)
    # evaluate interior nodes (tip node: zero load)
    phi, a, ap = solve_bem(Vx, Vy, rr, rtip, np.broadcast_to(CHORD, Vx.shape), np.broadcast_to(theta, Vx.shape),
                           np.broadcast_to(AFID, Vx.shape), aidrag=aidrag, tidrag=tidrag)
    if skew:
        # Pitt/Peters redistribution (AeroDyn SkewRedistr_Mod=1): a * (1 + 15 pi/32 tan(chi/2) r/R cos(psi - psi_w))
        # skew angle from the disc-average inflow; wake skewed towards the in-plane wind direction (+up)
        vin = np.mean(np.sum(wind * up, axis=-1))
        vn = np.mean(np.sum(wind * es, axis=-1))
        chi0 = math.atan2(vin, vn)
        abar = np.mean(a[:, 5:-2])
        chi = (0.6 * abar + 1) * chi0
        a = a * (1 + 15 * np.pi / 32 * math.tan(chi / 2) * rr / rtip * np.cos(P))
        phi = np.arctan2(Vx * (1 - a), Vy * (1 + ap))
    W2 = (Vx * (1 - a)) ** 2 + (Vy * (1 + ap)) ** 2
    cl, cd = coeffs(np.broadcast_to(AFID, Vx.shape), phi - theta)
    qd = 0.5 * RHO * W2 * CHORD
    fn = qd * (cl * np.cos(phi) + cd * np.sin(phi))  # along n, per unit span length
    ft = qd * (cl * np.sin(phi) - cd * np.cos(phi))  # along t (driving)
    fn[:, -1] = 0.0
    ft[:, -1] = 0.0
    # per unit length along the blade; integrate along the span s (trapezoid, like AeroDyn's line mesh)
    thrust_l = fn * np.cos(kap)[None, :]  # shaft component of the normal force
    torque_l = ft * rad[None, :]
    Tb = np.trapezoid(thrust_l, s, axis=1)
    Qb = np.trapezoid(torque_l, s, axis=1)
    return B * Tb.mean(), B * Qb.mean(), dict(a=a, phi=phi, Vx=Vx, Vy=Vy, fn=fn, ft=ft, rad=rad, kap=kap)


def coefs(V, omega, pitch_deg, R=63.0, **kw):
    T, Q, _ = rotor(V, omega, pitch_deg, **kw)
    q = 0.5 * RHO * np.pi * R * R * V * V
    return T / q, Q / q / R


def blade_geometry(tip_defl, precone_deg=2.5, foreshorten=True):
    """rad (distance from the shaft), axial (downwind from apex), kap (local upwind cone) per node; tip_defl
    may be an array (n,) -> outputs (n, nodes)."""
    s = SPAN
    L = SPAN[-1]
    x = s / L
    w1, dw1 = mode_shape(x, 'Fl1')
    td = np.atleast_1d(np.asarray(tip_defl, float))[:, None]
    w = td * w1[None, :] / w1[-1]
    slope = td * dw1[None, :] / w1[-1] / L
    if foreshorten:
        seg = 0.5 * (slope[:, 1:] ** 2 + slope[:, :-1] ** 2) / 2 * np.diff(s)[None, :]
        short = np.concatenate([np.zeros((td.shape[0], 1)), np.cumsum(seg, axis=1)], axis=1)
    else:
        short = np.zeros_like(w)
    kap0 = math.radians(precone_deg)
    rb = R_HUB + s[None, :] - short
    rad = rb * math.cos(kap0) + w * math.sin(kap0)
    axial = -rb * math.sin(kap0) + w * math.cos(kap0)
    kap = kap0 - np.arctan(slope)
    return rad, axial, kap


def rotor_series(u_fun, omega, pitch_deg, tilt_deg, tip_defl, v_hub, hub_ht=90.0, n_az=24, precone_deg=2.5,
                 shear=None, V=None):
    """Quasi-steady BEM thrust/torque time series. u_fun(k, r, psi) -> streamwise wind at sample k for arrays
    r (m from the hub centre in the rotor plane) and psi (azimuth from the top towards +y)."""
    n = len(omega)
    rad, axial, kap = blade_geometry(tip_defl, precone_deg)
    T = np.empty(n)
    Q = np.empty(n)
    psis = np.arange(n_az) * 2 * np.pi / n_az
    rtip = (R_HUB + SPAN[-1]) * math.cos(math.radians(precone_deg))
    for k in range(n):
        tau = math.radians(tilt_deg[k])
        es = np.array([math.cos(tau), 0.0, -math.sin(tau)])
        up = np.array([math.sin(tau), 0.0, math.cos(tau)])
        ey = np.array([0.0, 1.0, 0.0])
        P = psis[:, None]
        d = np.cos(P)[..., None] * up + np.sin(P)[..., None] * ey
        t = -np.sin(P)[..., None] * up + np.cos(P)[..., None] * ey
        kk = kap[k][None, :, None]
        nvec = np.sin(kk) * d + np.cos(kk) * es
        pos = rad[k][None, :, None] * d + axial[k][None, :, None] * es
        rr_plane = np.hypot(pos[..., 1], pos[..., 2])
        ps = np.arctan2(pos[..., 1], pos[..., 2])
        if u_fun is None:
            ux = V[k] * np.maximum((hub_ht + pos[..., 2]) / 90.0, 1e-3) ** shear
        else:
            ux = u_fun(k, rr_plane, ps)
        wind = np.zeros(pos.shape)
        wind[..., 0] = ux - v_hub[k]
        Vx = np.sum(wind * nvec, axis=-1)
        Vy = omega[k] * rad[k][None, :] - np.sum(wind * t, axis=-1)
        theta = TWIST + math.radians(pitch_deg[k])
        rr = np.broadcast_to(rad[k][None, :], Vx.shape)
        phi, a, ap = solve_bem(Vx, Vy, rr, rtip, np.broadcast_to(CHORD, Vx.shape), np.broadcast_to(theta, Vx.shape),
                               np.broadcast_to(AFID, Vx.shape), n_iter=40)
        W2 = (Vx * (1 - a)) ** 2 + (Vy * (1 + ap)) ** 2
        cl, cd = coeffs(np.broadcast_to(AFID, Vx.shape), phi - theta)
        qd = 0.5 * RHO * W2 * CHORD
        fn = qd * (cl * np.cos(phi) + cd * np.sin(phi))
        ft = qd * (cl * np.sin(phi) - cd * np.cos(phi))
        fn[:, -1] = 0.0
        ft[:, -1] = 0.0
        T[k] = B * np.trapezoid(fn * np.cos(kap[k])[None, :], SPAN, axis=1).mean()
        Q[k] = B * np.trapezoid(ft * rad[k][None, :], SPAN, axis=1).mean()
    return T, Q


Bd = '/work/shared/reference/openfast/runs/'
mr = 109389.852
g = 9.80665


def load(case, step=40):
    r = read_openfast(f'{Bd}{case}/{case}.outb')
    t = np.asarray(r.t, float)
    x = {c: np.asarray(r[c], float) for c in ['RotSpeed', 'BldPitch1', 'PtfmPitch', 'TTDspFA', 'PtfmSurge',
                                              'RotThrust', 'LSShftTq', 'OoPDefl1', 'TwHt9ALxt', 'Wind1VelX',
                                              'PtfmHeave']}
    pit = np.deg2rad(x['PtfmPitch'])
    ttop = pit + 1.5 * x['TTDspFA'] / 77.6
    Taero = x['RotThrust'] * 1e3 - mr * g * np.sin(math.radians(5) + ttop) + mr * x['TwHt9ALxt']
    dt = t[1] - t[0]
    sos = butter(4, 0.5, fs=1/dt, output='sos')
    xh = sosfiltfilt(sos, x['PtfmSurge'] + 89.6 * np.sin(pit) + x['TTDspFA'])
    vhub = np.gradient(xh, dt)
    zhub = 87.6 * np.cos(pit) + 1.96 * np.cos(pit) + 5.02 * np.sin(pit) + x['PtfmHeave']
    idx = np.arange(0, len(t), step)
    return dict(t=t[idx], omega=x['RotSpeed'][idx] * math.pi / 30, pitch=x['BldPitch1'][idx],
                tilt=5 + np.degrees(ttop[idx]), defl=x['OoPDefl1'][idx], vhub=vhub[idx], zhub=zhub[idx], Taero=Taero,
                Q=x['LSShftTq'] * 1e3, V=x['Wind1VelX'][idx], Taero_s=Taero[idx], Q_s=x['LSShftTq'][idx]*1e3)


def field(case):
    f = np.load(f'{Bd}{case}/{case}.inflow.npz')
    return f['t'], f['polar_u'].astype(float), f['polar_radii'], f['polar_azimuth_rad'], f['disc_mean_u'].astype(float)


def make_ufun(case, times, scale=1.0):
    tf, pu, rr, az, dm = field(case)
    idx = np.clip(np.searchsorted(tf, times), 0, len(tf) - 1)
    naz = len(az)
    daz = az[1] - az[0]

    def u(k, r, psi):
        fld = pu[idx[k]]
        fr = np.clip(r / rr[-1] * (len(rr) - 1), 0, len(rr) - 1.000001)
        i = fr.astype(int)
        wr = fr - i
        fa = (psi % (2 * np.pi)) / daz
        j = fa.astype(int) % naz
        wa = fa - np.floor(fa)
        j1 = (j + 1) % naz
        v = (1 - wr) * ((1 - wa) * fld[i, j] + wa * fld[i, j1]) + wr * ((1 - wa) * fld[i + 1, j] + wa * fld[i + 1, j1])
        # extrapolate beyond 60 m with the outermost ring
        return v * scale
    return u, dm[idx]


# ---------------------------------------------------------------------------------------------------------------
# AeroDyn driver (OpenFAST v5.0.0, commit 2895884d) results, steady wind, rigid blades, 30 s, mean of the last 15 s.
# "T" config = the table's conditions (tilt 5 deg, hub 90 m, precone 2.5, shear 0.2); "O" config = OpenFAST's mean
# elevation of the shaft (5 deg + platform pitch + tower-top slope: 10.26 deg at 12 m/s, 7.94 deg at 8 m/s) and the
# lowered hub (89.13 / 89.4 m). deck = the run's AeroDyn file (UA_Mod=3, TwrPotent=1, Skew_Mod=1); noUA = UA_Mod=0;
# bare = UA_Mod=0, TwrPotent=0, Skew_Mod=0; *_d = the mean flap deflection (mode-1 shape, tip 5.11 / 3.23 m)
# entered as blade curvature (BlCrvAC, BlCrvAng). AX = axisymmetric (tilt 0, precone 0, no shear). N = thrust (kN),
# torque (kN m). 12 m/s: 12.0957 rpm, pitch 1.3175 deg; 8 m/s: 8.187 m/s, 9.235 rpm, pitch 0.
AERODYN_DRIVER = {
    'T12_bare': (713.9, 4634.6), 'T12_noUA': (713.5, 4625.9), 'T12_deck': (688.0, 4458.2),
    'O12_bare': (700.3, 4473.0), 'O12_noUA': (700.4, 4460.2), 'O12_deck': (674.9, 4294.1),
    'O12_noUA_d': (696.3, 4380.8), 'O12_deck_d': (670.2, 4205.9),
    'T08_bare': (391.6, 2037.8), 'T08_noUA': (391.6, 2033.4), 'T08_deck': (374.6, 1930.3),
    'O08_bare': (387.9, 1998.3), 'O08_noUA': (388.1, 1992.4), 'O08_deck': (371.1, 1889.7),
    'O08_noUA_d': (387.8, 1972.1), 'O08_deck_d': (370.8, 1867.9),
    'AX12_noUA': (727.2, 4770.6), 'AX12_deck': (701.0, 4586.7),
    'AX08_noUA': (398.9, 2098.2), 'AX08_deck': (381.0, 1984.8),
}
# AX12, sectional Cl with UA_Mod=3 / static polar in perfectly steady axisymmetric inflow (nodes 6-12):
# DU35 -2.0/-6.9 %, DU30 -0.8 %, DU25 -11.6/-12.7 %, DU21 -8.9/-8.8 %, NACA64 0 % (Cd 0.0065 vs 0.0057: its UA Cd0).
# Cause: the airfoil files' UA constants C_nalpha (DU35 7.18, DU25 6.45, DU21 6.21 /rad) are 8-12 % below the static
# polars' normal-force slopes (7.81, 7.25, 6.78 /rad), so the B-L separation point saturates at f = 1 and the UA
# lift stays on the lower linear line (OpenFAST r-test issue #20, "UA changes the mean lift, e.g. DU25").


# Mean-load ratio UA_Mod=3 / UA_Mod=0 from the AeroDyn driver, table conditions (tilt 5 deg, precone 2.5 deg, shear 0.2,
# hub 90 m, rigid, V = 10 m/s, mean over the last 2 of 4 revolutions). Rows: TSR 5.5..9.5 step 0.5; columns: pitch
# 0..12 deg step 2. Valid where the loads are not near zero (the high-TSR/high-pitch corner, NaN here, is not).
UA_RATIO_TSR = np.arange(5.5, 9.51, 0.5)
UA_RATIO_PITCH_DEG = np.arange(0.0, 12.1, 2.0)
UA_RATIO_THRUST = np.array([
        [0.997, 0.983, 0.970, 0.960, 0.952, 0.946, 0.936],
        [0.984, 0.971, 0.960, 0.953, 0.948, 0.942, 0.945],
        [0.972, 0.961, 0.955, 0.951, 0.946, 0.939, 1.006],
        [0.964, 0.956, 0.953, 0.949, 0.945, 0.937, np.nan],
        [0.958, 0.954, 0.952, 0.949, 0.945, 0.950, np.nan],
        [0.956, 0.953, 0.951, 0.949, 0.945, np.nan, np.nan],
        [0.955, 0.952, 0.951, 0.950, 0.945, np.nan, np.nan],
        [0.954, 0.952, 0.952, 0.951, 0.946, np.nan, np.nan],
        [0.954, 0.952, 0.953, 0.952, 0.956, np.nan, np.nan],
    ])
UA_RATIO_TORQUE = np.array([
        [1.003, 0.989, 0.971, 0.955, 0.945, 0.938, 0.929],
        [0.991, 0.973, 0.956, 0.946, 0.939, 0.934, 0.937],
        [0.976, 0.959, 0.948, 0.941, 0.935, 0.929, 1.009],
        [0.963, 0.950, 0.944, 0.938, 0.934, 0.921, np.nan],
        [0.952, 0.946, 0.941, 0.935, 0.933, 0.933, np.nan],
        [0.946, 0.943, 0.937, 0.933, 0.930, np.nan, np.nan],
        [0.943, 0.940, 0.934, 0.935, 0.924, np.nan, np.nan],
        [0.940, 0.936, 0.933, 0.937, 0.915, np.nan, np.nan],
        [0.936, 0.932, 0.931, 0.935, 0.912, np.nan, np.nan],
    ])


def write_driver(out_dir, name, ad_file, hub_ht, tilt_deg, cases, precone_deg=2.5):
    """Write an AeroDyn driver file (basic HAWT, combined cases: (V, PLExp, rpm, pitch_deg, tmax))."""
    rows = '\n'.join(f'{v:.4f}  {pl:.3f}  {rpm:.4f}  {p:.4f}  0.  0.0125  {tm:.1f}  0  0  0'
                     for v, pl, rpm, p, tm in cases)
    txt = f'''----- AeroDyn Driver Input File ---------------------------------------------------------
rotor-gap study
----- Input Configuration ---------------------------------------------------------------
False           Echo
        0       MHK
        3       AnalysisType
       11.0     TMax
        0.0125  DT
"{ad_file}"      AeroFile
----- Environmental Conditions ----------------------------------------------------------
      1.225     FldDens
  1.464E-05     KinVisc
        335     SpdSound
     101325     Patm
       2000     Pvap
        320     WtrDpth
----- Inflow Data -----------------------------------------------------------------------
          0      CompInflow
"unused"         InflowFile
       12.0      HWindSpeed
         90      RefHt
       0.20      PLExp
----- SeaState Data [used only when MHK = 1 or 2] ---------------------------------------
          0     CompSeaSt
"unused"        SeaStFile
----- Turbine Data ----------------------------------------------------------------------
1               NumTurbines
----- Turbine(1) Geometry ---------------------------------------------------------------
        True    BasicHAWTFormat(1)
       0,0,0    BaseOriginInit(1)
           3    NumBlades(1)
         1.5    HubRad(1)
    {hub_ht:.4f}  HubHt(1)
     -5.0191    Overhang(1)
    {-tilt_deg:.4f}  ShftTilt(1)
    {-precone_deg:.4f}  Precone(1)
     1.96256    Twr2Shft(1)
----- Turbine(1) Motion [used only when AnalysisType=1] ---------------------------------
0               BaseMotionType(1)
1               DegreeOfFreedom(1)
0.0             Amplitude(1)
0.0             Frequency(1)
""              BaseMotionFileName(1)
0               NacYaw(1)
12.1            RotSpeed(1)
0               BldPitch(1)
----- Time-dependent Analysis [used only when AnalysisType=2, numTurbines=1] ------------
"unused"         TimeAnalysisFileName
-----  Combined-Case Analysis [used only when AnalysisType=3, numTurbines=1 -------------
         {len(cases)}  NumCases
HWndSpeed  PLExp  RotSpd  Pitch   Yaw   dT    Tmax  DOF  Amplitude Frequency
(m/s)      (-)    (rpm)   (deg)  (deg)  (s)   (s)   (-)   (-)       (Hz)
{rows}
----- Output Settings -------------------------------------------------------------------
"ES15.8E2"       OutFmt
1                OutFileFmt
0                WrVTK
1                WrVTK_Type
2                VTKHubRad
-1,-1,-1,2,2,2   VTKNacDim
'''
    Path(out_dir, f'{name}.dvr').write_text(txt)


def write_aerodyn(out_path, ua=3, twr=1, skew=1, blade_file=None):
    """Copy of the run's AeroDyn file with UA_Mod/TwrPotent/Skew_Mod switched and rotor outputs requested.
    The copy keeps the relative airfoil paths ../../decks/..., so place it two levels below a 'decks' link."""
    s = Path(Bd, 'd_steady12_Hs2p5_Tp10', 'd_steady12_Hs2p5_Tp10_AeroDyn.dat').read_text()
    s = re.sub(r'^\s*3\s+UA_Mod', f'{ua}                      UA_Mod', s, flags=re.M)
    s = re.sub(r'^\s*1\s+TwrPotent', f'{twr}                      TwrPotent', s, flags=re.M)
    s = re.sub(r'^\s*1\s+Skew_Mod', f'{skew}                      Skew_Mod', s, flags=re.M)
    s = re.sub(r'^\s*True\s+TwrAero', 'False                  TwrAero', s, flags=re.M)
    s = s.replace('"RtArea"                           \n"B1N3Clrnc, B2N3Clrnc, B3N3Clrnc"  ',
                  '"RtAeroFxh, RtAeroMxh, RtAeroCp, RtAeroCt, RtTSR, RtSkew, RtVAvgxh, RtArea"')
    if blade_file:
        s = s.replace('"../../decks/5MW_Baseline/NRELOffshrBsline5MW_AeroDyn_blade.dat"', f'"{blade_file}"')
    Path(out_path).write_text(s)


def openfast_point(case):
    """Mean OpenFAST operating point and rotor loads (aerodynamic thrust: RotThrust minus the rotor weight along the
    shaft, elevation 5 deg + PtfmPitch + 1.5 TTDspFA / 77.6 m)."""
    r = read_openfast(f'{Bd}{case}/{case}.outb')

    def m(c):
        return float(np.mean(np.asarray(r[c], float)))

    pit = math.radians(m('PtfmPitch'))
    elev = math.radians(5.0) + pit + 1.5 * m('TTDspFA') / 77.6
    return dict(V=m('Wind1VelX'), omega=m('RotSpeed') * math.pi / 30, pitch=m('BldPitch1'), elev_deg=math.degrees(elev),
                T=m('RotThrust') * 1e3 - mr * g * math.sin(elev), Q=m('LSShftTq') * 1e3, defl=m('OoPDefl1'))


def main():
    from surrogates.aero import rotor_coefficients, rotor_table
    tab = rotor_table()
    q12 = 0.5 * RHO * np.pi * 63.0 ** 2 * 12.0 ** 2
    op = openfast_point('d_steady12_Hs2p5_Tp10')
    lam = op['omega'] * 63 / op['V']
    ct, cq = rotor_coefficients(tab.tsr, tab.pitch_rad, tab.ct, tab.cq, lam, math.radians(op['pitch']))
    Ttab, Qtab = q12 * ct, q12 * 63 * cq
    print(f"12 m/s steady: TSR {lam:.3f}, pitch {op['pitch']:.3f} deg, shaft elevation {op['elev_deg']:.2f} deg, "
          f"OoPDefl1 {op['defl']:.2f} m")
    print(f"  OpenFAST  T {op['T']/1e3:.1f} kN  Q {op['Q']/1e3:.1f} kNm;  "
          f"table (hub wind)  T {Ttab/1e3:.1f}  Q {Qtab/1e3:.1f}"
          f"  -> gap T {op['T']/Ttab-1:+.2%} Q {op['Q']/Qtab-1:+.2%}")
    A = AERODYN_DRIVER
    steps = [
        ('AeroDyn quasi-steady BEM vs CCBlade table (same conditions)', A['T12_noUA'], (Ttab / 1e3, Qtab / 1e3)),
        ('UA_Mod=3 steady bias (deck vs UA off)', A['T12_deck'], A['T12_noUA']),
        ('extra shaft elevation 5 -> 10.26 deg + hub 89.13 m', A['O12_deck'], A['T12_deck']),
        ('mean flap deflection 5.11 m (AeroDyn, as curvature)', A['O12_deck_d'], A['O12_deck']),
    ]
    tot_t = tot_q = 1.0
    for name, a, b in steps:
        rt, rq = a[0] / b[0], a[1] / b[1]
        tot_t *= rt
        tot_q *= rq
        print(f'  {name:58s} T {rt-1:+.2%}  Q {rq-1:+.2%}')
    # platform motion and pitch/speed fluctuations: quasi-steady BEM, time series vs its own steady mean point
    d = load('d_steady12_Hs2p5_Tp10', step=80)
    n = len(d['t'])
    Ts = np.empty(n)
    Qs = np.empty(n)
    for k in range(n):
        a, b = rotor_series(None, d['omega'][k:k+1], d['pitch'][k:k+1], d['tilt'][k:k+1], d['defl'][k:k+1],
                            d['vhub'][k:k+1], hub_ht=d['zhub'][k], shear=0.2, V=d['V'][k:k+1])
        Ts[k], Qs[k] = a[0], b[0]
    T0, Q0, _ = rotor(12.0, op['omega'], op['pitch'], tilt_deg=op['elev_deg'], hub_ht=float(d['zhub'].mean()),
                      tip_defl=op['defl'])
    rt, rq = Ts.mean() / T0, Qs.mean() / Q0
    tot_t *= rt
    tot_q *= rq
    print(f"  {'platform motion + pitch/speed fluctuations (BEM series)':58s} T {rt-1:+.2%}  Q {rq-1:+.2%}")
    print(f"  {'product (predicted gap)':58s} T {tot_t-1:+.2%}  Q {tot_q-1:+.2%};  residual OF/predicted "
          f"T {op['T']/(Ttab*tot_t)-1:+.2%} Q {op['Q']/(Qtab*tot_q)-1:+.2%}")
    # 8 m/s turbulent: quasi-steady BEM with the run's polar wind field, static polars, then the UA factor
    case = 'c_op08_Hs2p0_Tp9'
    d = load(case, step=40)
    u, _ = make_ufun(case, d['t'])
    T, Q = rotor_series(u, d['omega'], d['pitch'], d['tilt'], d['defl'], d['vhub'])
    ua_t, ua_q = A['O08_deck_d'][0] / A['O08_noUA_d'][0], A['O08_deck_d'][1] / A['O08_noUA_d'][1]
    print(f"8 m/s turbulent (2 Hz samples): OpenFAST T {d['Taero_s'].mean()/1e3:.1f} kN "
          f"Q {d['Q_s'].mean()/1e3:.1f} kNm;"
          f" BEM (static polars, deflected, OF elevation) T {T.mean()/1e3:.1f} Q {Q.mean()/1e3:.1f} -> OF/BEM "
          f"T {d['Taero_s'].mean()/T.mean()-1:+.2%} Q {d['Q_s'].mean()/Q.mean()-1:+.2%}; UA factor (AeroDyn) "
          f"T {ua_t-1:+.2%} Q {ua_q-1:+.2%} -> residual T {d['Taero_s'].mean()/(T.mean()*ua_t)-1:+.2%} "
          f"Q {d['Q_s'].mean()/(Q.mean()*ua_q)-1:+.2%}")


if __name__ == '__main__':
    main()

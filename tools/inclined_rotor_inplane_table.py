"""Tabulate the in-plane (side) force of the inclined OC3 rotor against its in-plane wind, with AeroDyn.

What
    Runs OpenFAST's AeroDyn driver on the reference deck's AeroDyn input (through the helpers of
    ``tools/aerodyn_rotor_table.py``) at the surrogate's steady operating points (tip-speed ratio and blade pitch
    of :func:`surrogates.aero.operating_point` at 4-25 m/s), with the shaft inclined 5 and 10 deg in a uniform
    wind, for straight blades and for blades bent downwind along their first flap mode (``--tip``, default 5 m at
    the tip; ``--flap-deflection`` of that tool). The change of the rotor's aerodynamic side force ``RtAeroFyi``
    between the two inclinations, per m/s of the wind's component up the rotor plane ``W = V sin(inclination)``,
    is expressed in the surrogate's own blade in-plane gain ``G`` (one blade's in-plane force per m/s of wind,
    :func:`surrogates.aero.blade_inplane_sensitivity`) as

        eps = dF_y / (1.5 G dW),

    the share of the in-plane wind that each blade meets as a change of its axial wind ``-eps (W . e_r)``
    (``e_r`` the blade's radial direction): three blades then give the side force ``1.5 G eps W``. It writes
    ``eps`` for the straight blades and its growth per metre of tip deflection to
    ``surrogates/data/inclined_rotor_inplane.json``, which :func:`surrogates.aero.inclined_rotor_inplane` reads
    (the ``rotor_skew`` effect, with ``blade_deflection`` for the bent blades' share). For the tests it adds a check
    outside the table's conditions: straight and bent (5.26 m) blades at the shared steady-wind run's tip-speed
    ratio (6.65), pitch (1 and 2 deg) and inclination (10.2 deg).

    It also yaws the rotor (inclined by the second inclination) +/- ``--yaw`` deg in the wind, straight and bent,
    and writes the ``lateral`` block: one blade's share of the side force along the lateral in-plane wind
    ``w_y = -V sin(yaw)``, of the yaw moment across it (AeroDyn's skewed wake and the blades' cone) and of the tilt
    moment (the advancing blades', a check on ``yaw_moment_change_Nm``'s moment), each straight and per metre of
    bend, which :func:`surrogates.aero.inplane_wind_loads` reads; and, as a check of the rotor's symmetry, the
    moment across the wind up the disc from the inclined runs' tilt moment.

Why
    OpenFAST's rotor in its steady 12 m/s sheared wind, platform held at the steady run's mean position
    (``tools/openfast_blade_flex_runs.py``), puts a side force of -10.1 kN on the yaw bearing (``YawBrFyp``) with
    flexible blades and -19.0 kN with rigid ones; in still water with the platform free the flexible rotor's mean
    sway is -0.33 m, the rigid one's -0.55 m (the shared steady-wind run: -0.33 m). The shear's side force
    (each blade's in-plane force grows with its wind, more at the top) is what the surrogate had, from a
    blade-element model of straight blades in an aligned rotor. In the inclined rotor two things take some of it
    back, because the wind's in-plane component ``V sin(inclination)`` (up the disc) is met differently at the
    top and the bottom: a blade coned downwind (its flap deflection, less the deck's 2.5 deg of upwind precone)
    takes part of that in-plane wind as axial wind (less at the top, more at the bottom: a gradient against the
    shear), and AeroDyn's skewed-wake model (``Skew_Mod = 1``, Pitt and Peters) raises the induction on the disc's
    downwind side (the top). At tip-speed ratio 6.65 and 1 deg of pitch the driver gives, inclined 10.2 deg:
    -0.45 kN with straight blades, +3.16 kN bent 5.26 m, -4.38 kN without the skewed-wake model (-0.73 kN aligned),
    and with shear 0.2 as well -13.8 / -9.7 / -17.3 kN.

    The rotor's tilt moment changes likewise (-0.43 MN m bent 5.26 m, -0.55 MN m from the skewed wake, at 10.2 deg);
    those are not tabulated: the tilt and yaw moments' gains (:data:`surrogates.model.ROTOR_ASYMMETRY`) are
    calibrated on OpenFAST's own runs and hold them.

How
    Each (inclination, blade) pair is one driver run of combined cases, one per wind speed, at 12 rpm (400 steps of
    the deck's DT per revolution) with the wind ``V' = Omega R / lambda`` that gives the operating point's
    tip-speed ratio (the loads are non-dimensional in the wind speed: the polars carry no Reynolds number), loads
    averaged over the last of ``--revs`` revolutions. ``G`` at ``V'`` is ``G(V) V' / V`` (the same tip-speed ratio
    and pitch). Inclinations 5 and 10 deg rather than 0 and 10: blades bent 5 m downwind would meet AeroDyn's tower
    potential flow in an untilted rotor (a "tower strike" stops the driver).

Usage (maintainer tool, not run by the tests; about 4 minutes on one core)::

    python tools/inclined_rotor_inplane_table.py --driver /tmp/of/build/modules/aerodyn/aerodyn_driver \\
        [--shared ../shared] [--tip 5] [--workdir DIR]

The driver must be the OpenFAST v5.0.0 build of the reference runs (see ``tools/aerodyn_rotor_table.py``).
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import aerodyn_rotor_table as art  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DEFAULT_OUT = REPO / "surrogates" / "data" / "inclined_rotor_inplane.json"
OUTPUTS = ("RtAeroFxh", "RtAeroMxh", "RtAeroFxi", "RtAeroFyi", "RtAeroFzi", "RtAeroMxi", "RtAeroMyi", "RtAeroMzi")
RPM = 12.0


def driver_run(driver: Path, work: Path, ad_text: str, inp: dict, tilt: float, cases: list[tuple[float, ...]],
               revs: int) -> list[dict[str, float]]:
    """Mean rotor loads (last revolution) of combined cases ``(wind m/s, pitch deg)`` or ``(wind m/s, pitch deg, yaw
    deg)`` at inclination ``tilt``."""
    work.mkdir(parents=True, exist_ok=True)
    geo, env = inp["geo"], inp["env"]
    dt = env["DT"]
    n_rev = int(round(60.0 / RPM / dt))
    rows = [(c[0], 0.0, RPM, c[1], dt, revs * 60.0 / RPM, *c[2:]) for c in cases]
    (work / "AeroDyn.dat").write_text(ad_text)
    (work / "incl.dvr").write_text(art.driver_text("AeroDyn.dat", geo, env, tilt, rows))
    proc = subprocess.run([str(driver), "incl.dvr"], cwd=work, capture_output=True, text=True, errors="replace")
    log = proc.stdout + proc.stderr
    (work / "incl.log").write_text(log)
    if proc.returncode != 0 or "terminated normally" not in log:
        raise RuntimeError(f"aerodyn_driver failed in {work} (rc {proc.returncode}):\n" + "\n".join(
            log.splitlines()[-15:]))
    out = []
    t = math.radians(tilt)
    for k in range(len(rows)):
        ch = art.read_driver_output(work / f"incl.{k + 1}.out")
        row = {n: float(ch[n][-n_rev:].mean()) for n in OUTPUTS}
        # the yaw moment about the rotor plane's vertical axis (hub axes): the inertial RtAeroMzi of a tilted shaft
        # also carries the aerodynamic torque's projection Q sin(tilt) (0.8 MN m at 10 deg and rated torque)
        row["yaw_hub"] = row["RtAeroMzi"] * math.cos(t) + row["RtAeroMxi"] * math.sin(t)
        out.append(row)
    return out


def main(argv: list[str] | None = None) -> int:
    from surrogates.aero import blade_inplane_gain, operating_point, rotor_table

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--driver", required=True, help="aerodyn_driver binary (OpenFAST v5.0.0 build)")
    ap.add_argument("--shared", default=str(art.DEFAULT_SHARED), help="shared folder (default ../shared)")
    ap.add_argument("--tip", type=float, default=5.0, help="tip deflection of the bent blades, m (default 5)")
    ap.add_argument("--tilts", type=float, nargs=2, default=(5.0, 10.0), help="the two inclinations, deg")
    ap.add_argument("--wind", type=float, nargs="+", default=list(np.arange(4.0, 25.01, 1.0)),
                    help="wind speeds of the operating points, m/s (default 4..25)")
    ap.add_argument("--revs", type=int, default=4, help="revolutions per case (default 4)")
    ap.add_argument("--yaw", type=float, default=3.0,
                    help="the nacelle's yaw (+/-, deg) of the lateral runs, at the second inclination (default 3)")
    ap.add_argument("--workdir", default="/tmp/inclined_rotor_inplane", help="driver runs")
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    args = ap.parse_args(argv)

    shared = Path(args.shared)
    inp = art.deck_inputs(shared / "reference" / "openfast" / "runs" / art.DEFAULT_RUN)
    radius = rotor_table().radius
    omega = RPM * math.pi / 30.0
    winds = np.asarray(args.wind, float)
    ops = [operating_point(float(v)) for v in winds]
    lam = np.array([op.rotor_speed * radius / v for op, v in zip(ops, winds, strict=True)])
    pitch = np.array([math.degrees(op.pitch) for op in ops])
    v_drv = omega * radius / lam
    gain = np.array([blade_inplane_gain(float(v)) for v in winds])  # N/(m/s) at V
    gain_drv = gain * v_drv / winds

    ad_blade = (inp["ad"].parent / art._value(inp["ad"].read_text(), "ADBlFile(1)").strip('"')).resolve()
    work = Path(args.workdir)
    work.mkdir(parents=True, exist_ok=True)

    def aerodyn_text(tip: float) -> tuple[str, dict]:
        """The deck's AeroDyn input with blades bent ``tip`` m (0: straight) and this tool's outputs."""
        over = art.bent_blade_overrides(inp, tip, work / f"blade_{tip:g}m.dat")
        text, settings = art.aerodyn_copy(inp["ad"], over)
        return text.replace('"RtAeroFxh, RtAeroMxh, RtTSR, RtVAvgxh"', '"' + ", ".join(OUTPUTS) + '"'), settings

    loads: dict[tuple[float, float], list[dict[str, float]]] = {}
    for tip in (0.0, args.tip):
        ad_text, settings = aerodyn_text(tip)
        for tilt in args.tilts:
            loads[(tip, tilt)] = driver_run(Path(args.driver), work / f"tip{tip:g}_tilt{tilt:g}", ad_text, inp,
                                            tilt, list(zip(v_drv, pitch, strict=True)), args.revs)
            print(f"tip {tip:g} m, inclination {tilt:g} deg: done", flush=True)

    # an independent check at the shared steady-wind run's conditions (OpenFAST's rotor there: tip-speed ratio
    # 6.65, pitch 1.0 deg with flexible blades, 2.0 deg with rigid ones; shaft inclined 10.2 deg, tip 5.26 m):
    # the bent blades' side force against the straight ones', at one inclination (blades bent 5 m would strike
    # AeroDyn's tower in an untilted rotor)
    check = {"tip_speed_ratio": 6.65, "inclination_deg": 10.2, "tip_deflection_m": 5.26, "pitch_deg": [1.0, 2.0]}
    v_chk = omega * radius / check["tip_speed_ratio"]
    side = {}
    for tip in (0.0, check["tip_deflection_m"]):
        ad_text, _ = aerodyn_text(tip)
        res = driver_run(Path(args.driver), work / f"check_tip{tip:g}", ad_text, inp, check["inclination_deg"],
                         [(v_chk, p) for p in check["pitch_deg"]], args.revs)
        side["bent" if tip else "straight"] = [round(r["RtAeroFyi"], 1) for r in res]
    check.update(wind_speed=round(v_chk, 4), side_force_N=side)
    print("check:", check)

    # the lateral in-plane wind: the rotor inclined by the second inclination and yawed +/- args.yaw in the wind,
    # loads in hub axes (x down the shaft, y to the side, z up the disc); w_y = -V sin(yaw)
    lateral: dict[float, list[dict[str, float]]] = {}
    for tip in (0.0, args.tip):
        ad_text, _ = aerodyn_text(tip)
        cases = [(v, p, sgn * args.yaw) for v, p in zip(v_drv, pitch, strict=True) for sgn in (1.0, -1.0)]
        lateral[tip] = driver_run(Path(args.driver), work / f"tip{tip:g}_yaw{args.yaw:g}", ad_text, inp,
                                  args.tilts[1], cases, args.revs)
        print(f"tip {tip:g} m, yawed +/-{args.yaw:g} deg: done", flush=True)

    def hub_axes(row: dict[str, float], yaw_deg: float, tilt_deg: float) -> dict[str, float]:
        g, t = math.radians(yaw_deg), math.radians(tilt_deg)
        y_s = np.array([-math.sin(g), math.cos(g), 0.0])
        z_s = np.array([math.cos(g) * math.sin(t), math.sin(g) * math.sin(t), math.cos(t)])
        f = np.array([row["RtAeroFxi"], row["RtAeroFyi"], row["RtAeroFzi"]])
        m = np.array([row["RtAeroMxi"], row["RtAeroMyi"], row["RtAeroMzi"]])
        return {"side": float(f @ y_s), "yaw": float(m @ z_s), "tilt": float(m @ y_s)}

    def per_lateral_wind(tip: float, name: str) -> np.ndarray:
        """One blade's share (1/1.5 of the rotor's) of the load per m/s of lateral wind, at the operating point's
        own wind (the driver's slope times V / V')."""
        out = []
        for k, vd in enumerate(v_drv):
            plus = hub_axes(lateral[tip][2 * k], args.yaw, args.tilts[1])[name]
            minus = hub_axes(lateral[tip][2 * k + 1], -args.yaw, args.tilts[1])[name]
            dw = -2.0 * vd * math.sin(math.radians(args.yaw))
            out.append((plus - minus) / dw / 1.5 * winds[k] / vd)
        return np.array(out)

    lat = {}
    for name in ("side", "yaw", "tilt"):
        straight = per_lateral_wind(0.0, name)
        lat[name] = (straight, (per_lateral_wind(args.tip, name) - straight) / args.tip)

    t0, t1 = args.tilts
    d_w = v_drv * (math.sin(math.radians(t1)) - math.sin(math.radians(t0)))

    def eps(tip: float, name: str = "RtAeroFyi") -> np.ndarray:
        d_f = np.array([b[name] - a[name] for a, b in zip(loads[(tip, t0)], loads[(tip, t1)], strict=True)])
        return d_f / (1.5 * gain_drv * d_w)

    eps0 = eps(0.0)
    eps1 = (eps(args.tip) - eps0) / args.tip
    scale = (winds / v_drv) ** 2  # the driver's loads at the operating point's own wind

    def delta(tip: float, name: str) -> list[float]:
        return [round(float((b[name] - a[name]) * s), 1) for a, b, s in
                zip(loads[(tip, t0)], loads[(tip, t1)], scale, strict=True)]

    for v, e0, e1 in zip(winds, eps0, eps1, strict=True):
        print(f"V {v:5.1f} m/s: eps straight {e0:+.4f}, per m of tip deflection {e1:+.5f}")
    # the cross moment of the in-plane wind up the disc (the inclination's tilt moment), one blade's, per m/s:
    # the same physics as the lateral wind's yaw moment, turned a quarter turn (M = k e_x x W: tilt = -k W_z)
    cross_up = [-(b["RtAeroMyi"] - a["RtAeroMyi"]) / (1.5 * dw) * v / vd for a, b, dw, v, vd in
                zip(loads[(0.0, t0)], loads[(0.0, t1)], d_w, winds, v_drv, strict=True)]
    for k, v in enumerate(winds):
        print(f"V {v:5.1f} m/s, one blade per m/s of lateral wind: side force {lat['side'][0][k]:+8.1f} N "
              f"({lat['side'][1][k]:+7.1f}/m), yaw moment {lat['yaw'][0][k] / 1e3:+7.1f} kN m "
              f"({lat['yaw'][1][k] / 1e3:+6.2f}/m; up the disc, straight: {cross_up[k] / 1e3:+7.1f}), tilt moment "
              f"{lat['tilt'][0][k] / 1e3:+7.1f} kN m ({lat['tilt'][1][k] / 1e3:+6.2f}/m)")
    out = {
        "description": (
            "The inclined OC3 rotor's in-plane (side) force against the wind's component up the rotor plane, from "
            "OpenFAST's AeroDyn driver on the reference deck (tools/inclined_rotor_inplane_table.py): "
            "eps = dFy / (1.5 G dW), G one blade's in-plane force per m/s of wind "
            "(surrogates.aero.blade_inplane_sensitivity), W = V sin(inclination), between the two inclinations; "
            "eps(d) = eps_straight + eps_per_m * d for blades bent d m at the tip (first flap mode)."),
        "written_by": "tools/inclined_rotor_inplane_table.py",
        "written_on": datetime.date.today().isoformat(),
        "aerodyn_settings": settings,
        "inclinations_deg": [t0, t1],
        "tip_deflection_m": args.tip,
        "rotor_rpm_of_the_driver": RPM,
        "deck_sha256": {p.name: art.sha256(p) for p in (inp["ad"], inp["ed"], ad_blade)},
        "wind_speed": [float(v) for v in winds],
        "tip_speed_ratio": [round(float(x), 5) for x in lam],
        "pitch_deg": [round(float(x), 5) for x in pitch],
        "inplane_gain": [round(float(g), 3) for g in gain],
        "eps_straight": [round(float(x), 6) for x in eps0],
        "eps_per_m": [round(float(x), 7) for x in eps1],
        "side_force_change_N": {"straight": delta(0.0, "RtAeroFyi"), "bent": delta(args.tip, "RtAeroFyi")},
        "tilt_moment_change_Nm": {"straight": delta(0.0, "RtAeroMyi"), "bent": delta(args.tip, "RtAeroMyi")},
        "yaw_moment_change_Nm": {"straight": delta(0.0, "yaw_hub"), "bent": delta(args.tip, "yaw_hub")},
        "moment_axes": ("tilt: RtAeroMyi (the inertial y axis is the hub's); yaw: about the rotor plane's vertical "
                        "axis, RtAeroMzi cos(t) + RtAeroMxi sin(t) -- the inertial RtAeroMzi of the tilted shaft also "
                        "carries the aerodynamic torque's projection Q sin(t)"),
        "check_steady_run_conditions": check,
        "lateral": {
            "description": (
                "The rotor inclined by the second inclination and yawed +/- yaw_deg in the wind: one blade's share "
                "(the rotor's load / 1.5) per m/s of the lateral in-plane wind w_y = -V sin(yaw), in hub axes, at "
                "the operating point's own wind: the side force along w_y, the yaw moment about the disc's "
                "vertical (the cross moment M = k e_x x w of AeroDyn's skewed wake and the blades' cone) and the "
                "tilt moment (the advancing blades'); straight blades and the growth per m of tip deflection."),
            "yaw_deg": args.yaw,
            "inclination_deg": t1,
            "side_force_per_w": {"straight": [round(float(x), 3) for x in lat["side"][0]],
                                 "per_m": [round(float(x), 4) for x in lat["side"][1]]},
            "cross_moment_per_w": {"straight": [round(float(x), 2) for x in lat["yaw"][0]],
                                   "per_m": [round(float(x), 3) for x in lat["yaw"][1]]},
            "tilt_moment_per_w": {"straight": [round(float(x), 2) for x in lat["tilt"][0]],
                                  "per_m": [round(float(x), 3) for x in lat["tilt"][1]]},
            "cross_moment_up_the_disc_straight": [round(float(x), 2) for x in cross_up],
        },
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

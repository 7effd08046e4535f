"""Regenerate the rotor's steady Cp/Ct/Cq surfaces with OpenFAST's own AeroDyn (the OC3 reference deck).

What
    Runs OpenFAST's standalone AeroDyn driver (``aerodyn_driver``, OpenFAST v5.0.0) on the reference deck's own
    AeroDyn input (``<shared>/reference/openfast/runs/c_op12_Hs2p5_Tp10/*_AeroDyn.dat`` with its blade file and
    airfoil polars) over the (tip-speed ratio, pitch) grid of ROSCO's table ``surrogates/data/Cp_Ct_Cq.NREL5MW.txt``
    and writes ``surrogates/data/Cp_Ct_Cq.OC3_AeroDyn.txt`` in exactly that file's text format, so that
    ``surrogates.aero``'s parser reads it unchanged.

Why
    The ROSCO table (CCBlade) is 4-10 % stronger than the OpenFAST rotor (``tools/rotor_gap_bem.py``): the deck's
    unsteady airfoil model (UA_Mod = 3) lowers AeroDyn's mean lift even in steady wind, because the airfoil files'
    C_nalpha are below the static polars' slopes, and ROSCO's table already contains 5 deg shaft tilt and
    shear 0.2, which the surrogate then applies a second time. This table is the deck's rotor in ALIGNED, UNIFORM,
    STEADY inflow (shaft tilt 0, no shear, no yaw), so that the surrogate can add tilt, platform pitch and the
    disc-mean wind itself.

How
    Every aerodynamic setting of the deck's AeroDyn file is kept as it is (Wake_Mod = 1 BEMT, UA_Mod = 3, tip and
    hub loss, tangential induction, TwrPotent = 1, Skew_Mod = 1, DBEMT off, ...); only the output lists are
    changed (rotor channels requested, blade-node outputs and summary off) and the file paths are made absolute.
    The driver's "basic HAWT" turbine has the deck's ElastoDyn geometry (HubRad, PreCone, OverHang, Twr2Shft, tower
    top at TowerHt, AeroDyn's tower), rigid blades, no yaw and, by default, ShftTilt = 0 (the hub then sits at
    TowerHt + Twr2Shft) and a uniform wind (PLExp = 0). Each grid point is one combined case at a fixed rotor speed
    (12 rpm: exactly 400 steps of the deck's DT = 0.0125 s per revolution) with the wind speed V = Omega R / lambda,
    R = TipRad = 63 m; it runs ``--revs`` revolutions (default 3) from AeroDyn's initial state and the loads are
    averaged over the last revolution (exact mean of the once- and three-per-revolution tower-passage ripple).
    The change of that mean from the revolution before measures how settled UA and the induction are; it is
    printed per grid row and its maximum goes into the file header. Coefficients (R = 63 m, rho = FldDens):

        Ct = RtAeroFxh / (q pi R^2),   Cq = RtAeroMxh / (q pi R^3),   Cp = Cq lambda,   q = rho V^2 / 2,

    i.e. normalised exactly as ``surrogates.aero.RotorTable.loads`` un-normalises them (ROSCO's CCBlade divides by
    the coned disc pi (R cos 2.5 deg)^2 instead, 0.19 % in Ct and 0.29 % in Cq). With one polar table per airfoil
    (AFTabMod = 1) the coefficients do not depend on the wind speed; the file's single "z axis" wind value is
    nominal (11.4 m/s, as in ROSCO's file).

    Options allow other conditions for checks (``--ua-mod 0 --tilt 5 --shear 0.2`` reproduces ROSCO's conditions,
    ``--set NAME=VALUE`` overrides any other AeroDyn input, ``--compare`` prints the ratios to ROSCO's table),
    other grids (``--tsr``, ``--pitch``) and no output (``--no-write``). Results of each grid row are cached in
    ``--workdir`` (a rerun with the same settings reuses them).

    What AeroDyn gives there, kept as computed: all points settle (the last two revolutions' means differ by
    < 1.4e-4 in Ct); at lambda >= 11.5 with pitch <= -3 deg (very high induction, outside the OC3 controller's
    range: minimum pitch 0) Ct is irregular by a few per cent from point to point, also with UA off: AeroDyn's
    BEMT root changes branch there.

Usage (maintainer tool, not run by the tests; about 1.1 s of one core per grid point, 936 points in 17 min)::

    python tools/aerodyn_rotor_table.py --driver /tmp/rg/of/build/modules/aerodyn/aerodyn_driver \\
        [--shared ../shared] [--out surrogates/data/Cp_Ct_Cq.OC3_AeroDyn.txt] [--workdir DIR]
    # pipeline check against ROSCO's table (UA off, 5 deg tilt, shear 0.2), a few points, nothing written:
    python tools/aerodyn_rotor_table.py --driver ... --ua-mod 0 --tilt 5 --shear 0.2 \\
        --tsr 4 6 7.5 9 --pitch 0 2 5 10 --compare --no-write

The driver must be built from the same OpenFAST commit as the reference runs (v5.0.0, 2895884d;
``<shared>/reference/openfast/build.sh``: ``make aerodyn_driver`` in the cmake build tree, single precision).
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import json
import math
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SHARED = REPO.parent / "shared"
ROSCO_TABLE = REPO / "surrogates" / "data" / "Cp_Ct_Cq.NREL5MW.txt"
DEFAULT_OUT = REPO / "surrogates" / "data" / "Cp_Ct_Cq.OC3_AeroDyn.txt"
DEFAULT_RUN = "c_op12_Hs2p5_Tp10"
OPENFAST_COMMIT = "2895884d2be01862173c88d70f86b358d2f1a50a"
"""OpenFAST v5.0.0, the commit of the reference runs (the driver binary prints HEAD-HASH-NOTFOUND)."""
STEPS_PER_REV = 400
NOMINAL_WIND = 11.4
MARKERS = ("Pitch angle vector", "TSR vector", "Power coefficient", "Thrust coefficient", "Torque coefficient")
# words a table parser looks for (surrogates.aero: the markers above; ROSCO's load_from_txt: these, anywhere in a line)
_HEADER_FORBIDDEN = ("pitch angle", "tsr", "power", "thrust", "torque", "wind speed vector")


# ----------------------------------------------------------------------------------------------------------------
# inputs


def read_rosco_grid(path: Path = ROSCO_TABLE) -> tuple[np.ndarray, np.ndarray]:
    """Tip-speed ratios and pitch angles (deg) of a ROSCO-format table (the lines after the markers)."""
    lines = path.read_text().splitlines()

    def after(marker: str) -> int:
        return next(i for i, ln in enumerate(lines) if marker in ln) + 1

    pitch = np.array([float(v) for v in lines[after("Pitch angle vector")].split()])
    tsr = np.array([float(v) for v in lines[after("TSR vector")].split()])
    return tsr, pitch


def read_table(path: Path) -> dict[str, np.ndarray]:
    """A ROSCO-format table read with ``surrogates.aero._read_block`` the way ``rotor_table()`` reads its file."""
    from surrogates.aero import _read_block

    lines = path.read_text().splitlines()

    def after(marker: str) -> int:
        return next(i for i, ln in enumerate(lines) if marker in ln) + 1

    pitch = np.array([float(v) for v in lines[after("Pitch angle vector")].split()])
    tsr = np.array([float(v) for v in lines[after("TSR vector")].split()])
    return dict(tsr=tsr, pitch=pitch, cp=_read_block(lines, after("Power coefficient"), tsr.size),
                ct=_read_block(lines, after("Thrust coefficient"), tsr.size),
                cq=_read_block(lines, after("Torque coefficient"), tsr.size))


def _value(text: str, name: str) -> str:
    """First token of the input-file line whose second token is ``name`` (OpenFAST 'value name - comment')."""
    m = re.search(rf"^\s*(\S+)\s+{re.escape(name)}\s", text, re.M)
    if m is None:
        raise ValueError(f"{name} not found")
    return m.group(1)


def deck_inputs(run_dir: Path) -> dict:
    """The run's AeroDyn file, geometry (ElastoDyn) and environment (.fst) values the driver needs."""
    ad = next(run_dir.glob("*_AeroDyn.dat"))
    ed = next(run_dir.glob("*_ElastoDyn.dat"))
    fst = next(run_dir.glob("*.fst"))
    et, ft = ed.read_text(), fst.read_text()
    geo = {k: float(_value(et, k)) for k in ("NumBl", "TipRad", "HubRad", "PreCone(1)", "OverHang", "ShftTilt",
                                             "Twr2Shft", "TowerHt")}
    env = {k: float(_value(ft, k)) for k in ("DT", "AirDens", "KinVisc", "SpdSound", "Patm", "Pvap", "WtrDpth")}
    return dict(ad=ad, ed=ed, fst=fst, geo=geo, env=env)


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def aerodyn_copy(ad_path: Path, overrides: dict[str, str] | None = None) -> tuple[str, dict]:
    """The run's AeroDyn file with absolute file paths, rotor outputs, no node outputs/summary, and optional
    overrides {input name: value} (checks only).

    Returns the text and the deck's aerodynamic settings (for the header)."""
    text = ad_path.read_text()
    base = ad_path.parent

    def absolute(m: re.Match) -> str:
        p = m.group(1)
        return f'"{(base / p).resolve()}"' if p.startswith(".") else m.group(0)

    text = re.sub(r'"([^"\n]+\.dat)"', absolute, text)
    settings = {k: _value(text, k) for k in ("Wake_Mod", "UA_Mod", "TwrPotent", "TwrShadow", "Skew_Mod", "TipLoss",
                                             "HubLoss", "TanInd", "AIDrag", "TIDrag", "DBEMT_Mod", "AFTabMod",
                                             "BEM_Mod", "AoA34", "FLookup", "UseBlCm")}
    for name, value in (overrides or {}).items():
        text, n = re.subn(rf"^\s*\S+(\s+{re.escape(name)}\s)", lambda m, v=value: v + m.group(1), text, count=1,
                          flags=re.M)
        if n != 1:
            raise ValueError(f"AeroDyn input {name} not found")
    text, n = re.subn(r"^\s*\S+(\s+SumPrint\s)", r"False\1", text, count=1, flags=re.M)
    text, n2 = re.subn(r"^\s*\S+(\s+NBlOuts\s)", r"0\1", text, count=1, flags=re.M)
    text, n3 = re.subn(r"^\s*\S+(\s+BldNd_BladesOut\s)", r"0\1", text, count=1, flags=re.M)
    outs = '"RtAeroFxh, RtAeroMxh, RtTSR, RtVAvgxh"\n'
    text, n4 = re.subn(r"(OutList\s+- The next line.*?\n)(.*?)(END of OutList)",
                       lambda m: m.group(1) + outs + m.group(3), text, count=1, flags=re.S)
    if (n, n2, n3, n4) != (1, 1, 1, 1):
        raise ValueError("unexpected AeroDyn file layout")
    return text, settings


def flap_mode_shape(ed_path: Path) -> np.ndarray:
    """Coefficients of ``x^2 .. x^6`` of the blade's first flap mode in the ElastoDyn blade file the ElastoDyn
    input names (``BldFile(1)``, ``BldFl1Sh(2..6)``; x = span fraction from the root, shape 1 at the tip)."""
    text = ed_path.read_text()
    rel = _value(text, "BldFile(1)").strip('"')
    blade = (ed_path.parent / rel).resolve()
    bt = blade.read_text()
    return np.array([float(_value(bt, f"BldFl1Sh({k})")) for k in range(2, 7)])


def deflected_blade(ad_blade: Path, coeffs: np.ndarray, tip_deflection: float, out: Path) -> Path:
    """The AeroDyn blade file with the blade bent downwind along its first flap mode (tip ``tip_deflection`` m):
    each node's out-of-plane offset ``BlCrvAC`` gains ``delta phi(x)``, its cant ``BlCrvAng`` the slope
    ``atan(delta phi'(x) / L)`` (deg), and its span ``BlSpn`` loses the foreshortening of the bent blade
    ``1/2 int_0^r (delta phi'/L)^2 dr`` (a beam bends at constant length, as ElastoDyn's blades do:
    its ``AxRedBld``), L the blade length (the last node's span)."""
    lines = ad_blade.read_text().splitlines()
    rows = [i for i, ln in enumerate(lines) if len(ln.split()) == 7 and _is_numbers(ln.split())]
    span = np.array([float(lines[i].split()[0]) for i in rows])
    length = span[-1]

    def slope(x: np.ndarray) -> np.ndarray:  # d(delta phi)/dr
        return tip_deflection * sum(c * (k + 2) * x ** (k + 1) for k, c in enumerate(coeffs)) / length

    for i, r in zip(rows, span, strict=True):
        v = [float(t) for t in lines[i].split()]
        x = r / length
        xs = np.linspace(0.0, x, 401)
        v[0] = r - 0.5 * float(np.trapezoid(slope(xs) ** 2, xs * length))
        v[1] += tip_deflection * sum(c * x ** (k + 2) for k, c in enumerate(coeffs))
        v[3] += math.degrees(math.atan(float(slope(np.array(x)))))
        lines[i] = "  ".join(f"{a: .7E}" for a in v[:6]) + f"  {int(v[6])}"
    out.write_text("\n".join(lines) + "\n")
    return out


def bent_blade_overrides(inp: dict, tip_deflection: float, out: Path) -> dict[str, str]:
    """AeroDyn input overrides ``{"ADBlFile(i)": path}`` pointing all three blades at the deck's blade bent downwind
    by ``tip_deflection`` m (:func:`deflected_blade`, written to ``out``); ``{}`` for 0 (straight blades)."""
    if not tip_deflection:
        return {}
    ad_blade = (inp["ad"].parent / _value(inp["ad"].read_text(), "ADBlFile(1)").strip('"')).resolve()
    bent = deflected_blade(ad_blade, flap_mode_shape(inp["ed"]), tip_deflection, out)
    return {f"ADBlFile({i})": f'"{bent}"' for i in (1, 2, 3)}


def _is_numbers(tokens: list[str]) -> bool:
    try:
        [float(t) for t in tokens]
    except ValueError:
        return False
    return True


def driver_text(ad_file: str, geo: dict, env: dict, tilt_deg: float, cases: list[tuple]) -> str:
    """AeroDyn driver input: basic HAWT with the deck's geometry, combined cases (V, PLExp, rpm, pitch, dt, tmax) or
    (V, PLExp, rpm, pitch, dt, tmax, yaw): the nacelle yawed ``yaw`` deg (about the vertical) in the wind."""
    tilt = math.radians(tilt_deg)  # upwind end of the shaft up (OpenFAST's ShftTilt = -tilt_deg)
    hub_ht = geo["TowerHt"] + geo["Twr2Shft"] - geo["OverHang"] * math.sin(tilt)  # tower top stays at TowerHt
    rows = "\n".join(f"{v:.6f}  {pl:.4f}  {rpm:.6f}  {p:.4f}  {(yaw[0] if yaw else 0.0):.4f}  {dt:.6g}  {tm:.6f}"
                      "  0  0  0" for v, pl, rpm, p, dt, tm, *yaw in cases)
    return f"""----- AeroDyn Driver Input File ---------------------------------------------------------
tools/aerodyn_rotor_table.py: steady rotor coefficients of the OC3 reference deck
----- Input Configuration ---------------------------------------------------------------
False           Echo         - Echo input parameters to "<rootname>.ech"?
        0       MHK          - MHK turbine type (switch) {{0: not an MHK turbine}}
        3       AnalysisType - {{1: multiple turbines, 2: one turbine, time-dependent, 3: combined cases}}
       10.0     TMax         - Total run time [used only when AnalysisType/=3] (s)
  {env["DT"]:.6g}  DT           - Simulation time step [used only when AnalysisType/=3] (s)
"{ad_file}"      AeroFile - Name of the primary AeroDyn input file
----- Environmental Conditions ----------------------------------------------------------
  {env["AirDens"]:.6g}    FldDens      - Density of working fluid (kg/m^3)
  {env["KinVisc"]:.6g}    KinVisc      - Kinematic viscosity of working fluid (m^2/s)
  {env["SpdSound"]:.6g}    SpdSound     - Speed of sound in working fluid (m/s)
  {env["Patm"]:.6g}    Patm         - Atmospheric pressure (Pa)
  {env["Pvap"]:.6g}    Pvap         - Vapour pressure of working fluid (Pa)
  {env["WtrDpth"]:.6g}    WtrDpth      - Water depth (m)
----- Inflow Data -----------------------------------------------------------------------
          0      CompInflow  - Compute inflow wind velocities (switch) {{0=Steady Wind; 1=InflowWind}}
"unused"         InflowFile  - Name of the InflowWind input file [used only when CompInflow=1]
       10.0      HWindSpeed  - Horizontal wind speed [used only when CompInflow=0 and AnalysisType=1] (m/s)
  {hub_ht:.6f}   RefHt       - Reference height for horizontal wind speed [used only when CompInflow=0] (m)
        0.0      PLExp       - Power law exponent [used only when CompInflow=0 and AnalysisType=1] (-)
----- SeaState Data [used only when MHK = 1 or 2] ---------------------------------------
          0     CompSeaSt    - Compute wave velocities (switch) {{0=No Waves; 1=SeaState}}
"unused"        SeaStFile    - Name of the SeaState input file [used only when CompSeaSt=1]
----- Turbine Data ----------------------------------------------------------------------
1               NumTurbines  - Number of turbines
----- Turbine(1) Geometry ---------------------------------------------------------------
        True    BasicHAWTFormat(1) - basic inputs (next 7 lines)
       0,0,0    BaseOriginInit(1) - Coordinate of tower base in base coordinates (m)
  {int(geo["NumBl"])}             NumBlades(1)    - Number of blades (-)
  {geo["HubRad"]:.6g}      HubRad(1)       - Hub radius (m)
  {hub_ht:.6f}   HubHt(1)        - Hub height (m)
  {geo["OverHang"]:.6g}      Overhang(1)     - Overhang (m)
  {-tilt_deg:.6f}   ShftTilt(1)     - Shaft tilt (deg)
  {geo["PreCone(1)"]:.6g}      Precone(1)      - Blade precone (deg)
  {geo["Twr2Shft"]:.6g}      Twr2Shft(1)     - Vertical distance from the tower-top to the rotor shaft (m)
----- Turbine(1) Motion [used only when AnalysisType=1] ---------------------------------
0               BaseMotionType(1)      - Type of motion prescribed for this base {{0: fixed}}
1               DegreeOfFreedom(1)     - unused
0.0             Amplitude(1)           - unused
0.0             Frequency(1)           - unused
""              BaseMotionFileName(1)  - unused
0               NacYaw(1)              - Yaw angle (about z_t) of the nacelle (deg)
12.0            RotSpeed(1)            - Rotational speed of rotor in rotor coordinates (rpm)
0               BldPitch(1)            - Blade 1 pitch (deg)
----- Time-dependent Analysis [used only when AnalysisType=2, numTurbines=1] ------------
"unused"         TimeAnalysisFileName - unused
-----  Combined-Case Analysis [used only when AnalysisType=3, numTurbines=1] -------------
  {len(cases)}     NumCases     - Number of cases to run
HWndSpeed  PLExp  RotSpd  Pitch   Yaw   dT    Tmax  DOF  Amplitude Frequency
(m/s)      (-)    (rpm)   (deg)  (deg)  (s)   (s)   (-)   (-)       (Hz)
{rows}
----- Output Settings -------------------------------------------------------------------
"ES16.8E2"       OutFmt      - Format used for text tabular output
1                OutFileFmt  - Format for tabular (time-marching) output file (switch) {{1: text file [<RootName>.out]}}
0                WrVTK       - VTK visualization data output: (switch) {{0=none}}
1                WrVTK_Type  - Type of VTK visualization data: (switch) {{1=surfaces}}
2                VTKHubRad   - HubRadius for VTK visualization (m)
-1,-1,-1,2,2,2   VTKNacDim   - Nacelle Dimension for VTK visualization x0,y0,z0,Lx,Ly,Lz (m)
"""


# ----------------------------------------------------------------------------------------------------------------
# running


def read_driver_output(path: Path) -> dict[str, np.ndarray]:
    """Channels of a text output file of the AeroDyn driver."""
    lines = path.read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.split()[:1] == ["Time"])
    names = lines[i].split()
    data = np.array([[float(v) for v in ln.split()] for ln in lines[i + 2:] if ln.strip()])
    return {n: data[:, k] for k, n in enumerate(names)}


def case_warnings(log: str, n_cases: int) -> list[list[str]]:
    """The screen output's warnings and errors, attributed to the combined case that was running."""
    out: list[list[str]] = [[] for _ in range(n_cases)]
    parts = re.split(r"Running combined case (\d+)/\d+", log)
    for k in range(1, len(parts) - 1, 2):
        case = int(parts[k]) - 1
        for ln in re.split(r"[\r\n]+", parts[k + 1]):
            s = ln.strip()
            if not re.search(r"warning|error|not converge|fail|turned off", s, re.I):
                continue
            if "polar has constant data" in s:  # the cylinder root sections: UA off there, as in OpenFAST
                continue
            m = re.search(r"turned off due to low TSR\.\s+\(TSR = ([-0-9.Ee+]+)\)", s)
            if m and float(m.group(1)) >= 1.99:
                # lambda = 2 in AeroDyn's in-plane radius (63 cos 2.5 deg): BEM weight BlendCosine(1.998, 1, 2)
                # = 1 - 6e-6, i.e. no effect
                continue
            out[case].append(s[:200])
    return out


def run_row(driver: Path, work: Path, name: str, ad_text: str, inp: dict, args, lam: float,
            pitches: np.ndarray) -> dict:
    """All pitch angles of one tip-speed ratio in one driver run. Returns per-case means and diagnostics."""
    geo, env = inp["geo"], inp["env"]
    rad = geo["TipRad"]
    omega = args.rpm * math.pi / 30.0
    v = omega * rad / lam
    dt = env["DT"]
    t_rev = 60.0 / args.rpm
    n_rev = int(round(t_rev / dt))
    if abs(n_rev * dt - t_rev) > 1e-9:
        raise ValueError(f"--rpm {args.rpm}: a revolution is not a whole number of DT = {dt} s steps")
    tmax = args.revs * t_rev
    (work / "AeroDyn.dat").write_text(ad_text)
    cases = [(v, args.shear, args.rpm, float(p), dt, tmax) for p in pitches]
    dvr = work / f"{name}.dvr"
    dvr.write_text(driver_text("AeroDyn.dat", geo, env, args.tilt, cases))
    proc = subprocess.run([str(driver), dvr.name], cwd=work, capture_output=True, text=True, errors="replace")
    log = proc.stdout + proc.stderr
    (work / f"{name}.log").write_text(log)
    if proc.returncode != 0 or "terminated normally" not in log:
        tail = "\n".join(log.splitlines()[-15:])
        raise RuntimeError(f"aerodyn_driver failed on {name} (rc {proc.returncode}):\n{tail}")
    warns = case_warnings(log, len(cases))
    q = 0.5 * env["AirDens"] * v * v
    area = math.pi * rad * rad
    res = dict(tsr=lam, wind=v, pitch=[float(p) for p in pitches], ct=[], cq=[], cp=[], d_ct=[], d_cq=[],
               warnings=warns, tsr_out=[])
    for k in range(len(cases)):
        f = work / f"{name}.{k + 1}.out"
        ch = read_driver_output(f)
        fx, mx = ch["RtAeroFxh"], ch["RtAeroMxh"]
        if fx.size < 2 * n_rev + 1 or not np.all(np.isfinite(fx)) or not np.all(np.isfinite(mx)):
            raise RuntimeError(f"{f}: {fx.size} samples or non-finite loads")
        last = slice(fx.size - n_rev, fx.size)
        prev = slice(fx.size - 2 * n_rev, fx.size - n_rev)
        ct, cq = fx[last].mean() / (q * area), mx[last].mean() / (q * area * rad)
        res["ct"].append(float(ct))
        res["cq"].append(float(cq))
        res["cp"].append(float(cq * lam))
        res["d_ct"].append(float((fx[last].mean() - fx[prev].mean()) / (q * area)))
        res["d_cq"].append(float((mx[last].mean() - mx[prev].mean()) / (q * area * rad)))
        res["tsr_out"].append(float(ch["RtTSR"][last].mean()) if "RtTSR" in ch else float("nan"))
        if not args.keep:
            f.unlink()
    return res


def overrides(args) -> dict[str, str]:
    """AeroDyn input overrides of the command line (--ua-mod, --set NAME=VALUE)."""
    out = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise SystemExit(f"--set expects NAME=VALUE, got {item!r}")
        out[name.strip()] = value.strip()
    if args.ua_mod is not None:
        out["UA_Mod"] = str(args.ua_mod)
    return out


def settings_key(args, deck_sha: str, driver_sha: str) -> dict:
    return dict(overrides=overrides(args), tilt=args.tilt, shear=args.shear, rpm=args.rpm, revs=args.revs,
                deck=deck_sha, driver=driver_sha, flap_deflection=args.flap_deflection)


def run_grid(args, inp: dict, tsr: np.ndarray, pitch: np.ndarray) -> tuple[list[dict], float]:
    driver = Path(args.driver).resolve()
    work = Path(args.workdir) if args.workdir else Path(tempfile.mkdtemp(prefix="aerodyn_rotor_table_"))
    work.mkdir(parents=True, exist_ok=True)
    changed = overrides(args)
    changed.update(bent_blade_overrides(inp, args.flap_deflection, work / f"blade_flap{args.flap_deflection:g}m.dat"))
    ad_text, _ = aerodyn_copy(inp["ad"], changed)
    key = settings_key(args, sha256(inp["ad"]), sha256(driver))
    rows = []
    t0 = time.time()
    for i, lam in enumerate(tsr):
        name = f"tsr{lam:05.2f}".replace(".", "p")
        cache = work / f"{name}.json"
        if cache.exists():
            old = json.loads(cache.read_text())
            if old.get("key") == key and old["pitch"] == [float(p) for p in pitch]:
                rows.append(old)
                continue
        t1 = time.time()
        res = run_row(driver, work, name, ad_text, inp, args, float(lam), pitch)
        res["key"] = key
        res["seconds"] = time.time() - t1
        cache.write_text(json.dumps(res))
        rows.append(res)
        nw = sum(len(w) for w in res["warnings"])
        print(f"[{i + 1}/{len(tsr)}] lambda {lam:5.2f}  V {res['wind']:6.3f} m/s  {len(pitch)} pitches  "
              f"{res['seconds']:5.1f} s  max |dCt| {np.max(np.abs(res['d_ct'])):.2e}  "
              f"max |dCq| {np.max(np.abs(res['d_cq'])):.2e}  warnings {nw}", flush=True)
    seconds = sum(r["seconds"] for r in rows)
    print(f"work directory {work}; driver time {seconds:.0f} s (this call {time.time() - t0:.0f} s)")
    return rows, seconds


# ----------------------------------------------------------------------------------------------------------------
# output


def format_table(tsr, pitch, cp, ct, cq, header: list[str]) -> str:
    """The ROSCO text format of ``Cp_Ct_Cq.NREL5MW.txt`` (same line layout, separators and number formats)."""
    for ln in header:
        low = ln.lower()
        if any(w in low for w in _HEADER_FORBIDDEN) or any(m in ln for m in MARKERS):
            raise ValueError(f"header line would confuse a table parser: {ln!r}")
    out = [f"# {ln}".rstrip() + (" " if ln.startswith("-") else "") for ln in header]
    out += ["", f"# Pitch angle vector, {len(pitch)} entries - x axis (matrix columns) (deg)",
            "".join(f"{p:.1f}   " for p in pitch),
            f"# TSR vector, {len(tsr)} entries - y axis (matrix rows) (-)",
            "".join(f"{t:.1f}    " for t in tsr),
            "# Wind speed vector - z axis (m/s)", f"{NOMINAL_WIND:.1f}    ", ""]
    for title, m in (("# Power coefficient", cp), ("#  Thrust coefficient", ct), ("# Torque coefficient", cq)):
        out += [title, ""]
        out += ["".join(f"{x:.6f}   " for x in row) for row in m]
        out += ["", ""]
    return "\n".join(out[:-1]) + "\n"


def bilinear(tab: dict, name: str, lam: float, beta_deg: float) -> float:
    """Bilinear, clamped, like ``surrogates.aero.rotor_coefficients``."""
    tsr, pitch, m = tab["tsr"], tab["pitch"], tab[name]
    fl = min(max((lam - tsr[0]) / (tsr[1] - tsr[0]), 0.0), tsr.size - 1.000001)
    fb = min(max((beta_deg - pitch[0]) / (pitch[1] - pitch[0]), 0.0), pitch.size - 1.000001)
    i, j = int(fl), int(fb)
    wl, wb = fl - i, fb - j
    return float((1 - wl) * (1 - wb) * m[i, j] + wl * (1 - wb) * m[i + 1, j] + (1 - wl) * wb * m[i, j + 1]
                 + wl * wb * m[i + 1, j + 1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--driver", required=True, help="aerodyn_driver binary (OpenFAST v5.0.0 build)")
    ap.add_argument("--shared", default=str(DEFAULT_SHARED), help="shared folder (default ../shared)")
    ap.add_argument("--run", default=DEFAULT_RUN, help="reference run whose AeroDyn/ElastoDyn/.fst files are used")
    ap.add_argument("--out", default=str(DEFAULT_OUT), help="table file to write")
    ap.add_argument("--no-write", action="store_true", help="do not write the table")
    ap.add_argument("--workdir", default=None, help="driver work directory and per-row cache (default: a temp dir)")
    ap.add_argument("--keep", action="store_true", help="keep the driver's per-case output files")
    ap.add_argument("--tsr", type=float, nargs="+", default=None, help="tip-speed ratios (default: ROSCO's grid)")
    ap.add_argument("--pitch", type=float, nargs="+", default=None, help="pitch angles, deg (default: ROSCO's)")
    ap.add_argument("--ua-mod", type=int, default=None, help="override the deck's UA_Mod (checks only)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override an AeroDyn input, e.g. TwrPotent=0 (checks only; repeatable)")
    ap.add_argument("--tilt", type=float, default=0.0, help="shaft tilt, deg, upwind end up (default 0)")
    ap.add_argument("--shear", type=float, default=0.0, help="power-law shear exponent (default 0)")
    ap.add_argument("--flap-deflection", type=float, default=0.0, metavar="M",
                    help="blades bent downwind along their first flap mode, tip deflection M metres, at constant "
                         "length (default 0: the deck's straight blades)")
    ap.add_argument("--rpm", type=float, default=12.0, help="rotor speed (default 12: 400 steps per revolution)")
    ap.add_argument("--revs", type=int, default=3, help="revolutions per point; the last one is averaged")
    ap.add_argument("--compare", action="store_true", help="print ratios to ROSCO's table at the grid points")
    args = ap.parse_args(argv)
    if args.revs < 2:
        ap.error("--revs must be >= 2 (the revolution before the last measures the settling)")

    shared = Path(args.shared).resolve()
    run_dir = shared / "reference" / "openfast" / "runs" / args.run
    inp = deck_inputs(run_dir)
    rosco_tsr, rosco_pitch = read_rosco_grid()
    tsr = np.array(args.tsr if args.tsr else rosco_tsr, float)
    pitch = np.array(args.pitch if args.pitch else rosco_pitch, float)
    rows, seconds = run_grid(args, inp, tsr, pitch)
    ct = np.array([r["ct"] for r in rows])
    cq = np.array([r["cq"] for r in rows])
    cp = np.array([r["cp"] for r in rows])
    d_ct = np.array([r["d_ct"] for r in rows])
    d_cq = np.array([r["d_cq"] for r in rows])
    warned = [(r["tsr"], r["pitch"][j], w) for r in rows for j, w in enumerate(r["warnings"]) if w]
    for lam, p, w in warned:
        print(f"warning at lambda {lam}, pitch {p}: {w[0]} ({len(w)} lines)")
    k = np.unravel_index(np.argmax(cp), cp.shape)
    print(f"max Cp {cp[k]:.4f} at lambda {tsr[k[0]]}, pitch {pitch[k[1]]} deg; settling: max |dCt| over the last "
          f"revolution {np.abs(d_ct).max():.2e}, max |dCq| {np.abs(d_cq).max():.2e}")

    if args.compare:
        rosco = read_table(ROSCO_TABLE)
        print("lambda  pitch    Ct      Ct_ROSCO  ratio    Cq       Cq_ROSCO  ratio")
        for i, lam in enumerate(tsr):
            for j, p in enumerate(pitch):
                rt, rq = bilinear(rosco, "ct", lam, p), bilinear(rosco, "cq", lam, p)
                print(f"{lam:5.2f}  {p:6.2f}  {ct[i, j]:.5f}  {rt:.5f}  {ct[i, j] / rt:.4f}  "
                      f"{cq[i, j]:.6f}  {rq:.6f}  {cq[i, j] / rq:.4f}")

    if args.no_write:
        return 0
    driver = Path(args.driver).resolve()
    _, settings = aerodyn_copy(inp["ad"])
    changed = overrides(args)
    for name, value in changed.items():
        if name in settings:
            settings[name] = f"{value} (deck: {settings[name]})"
    airfoils = sorted((shared / "reference" / "openfast" / "decks" / "5MW_Baseline" / "Airfoils").glob("*.dat"))
    af_sha = hashlib.sha256(b"".join(sha256(p).encode() for p in airfoils)).hexdigest()
    blade = shared / "reference" / "openfast" / "decks" / "5MW_Baseline" / "NRELOffshrBsline5MW_AeroDyn_blade.dat"
    geo = inp["geo"]
    today = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    header = [
        "----- Rotor performance tables for the NREL-5MW wind turbine, OC3-Hywind OpenFAST deck (AeroDyn) -----",
        f"------------ Written on {today} by tools/aerodyn_rotor_table.py (fowt-env) ------------",
        f"OpenFAST v5.0.0 aerodyn_driver, commit {OPENFAST_COMMIT}, single precision;",
        f"  driver binary sha256 {sha256(driver)}",
        f"AeroDyn file reference/openfast/runs/{args.run}/{inp['ad'].name}",
        f"  sha256 {sha256(inp['ad'])}",
        f"  blade file sha256 {sha256(blade)}",
        f"  airfoil files (sorted Airfoils/*.dat): sha256 of their sha256s {af_sha}",
        f"Deck settings {'(OVERRIDDEN: ' + str(changed) + ')' if changed else 'kept'}: "
        f"Wake_Mod {settings['Wake_Mod']} (BEMT), UA_Mod {settings['UA_Mod']}, TwrPotent {settings['TwrPotent']}, "
        f"TwrShadow {settings['TwrShadow']}, Skew_Mod {settings['Skew_Mod']},",
        f"  TipLoss {settings['TipLoss']}, HubLoss {settings['HubLoss']}, TanInd {settings['TanInd']}, "
        f"AIDrag {settings['AIDrag']}, TIDrag {settings['TIDrag']}, DBEMT_Mod {settings['DBEMT_Mod']}, "
        f"AFTabMod {settings['AFTabMod']}, AoA34 {settings['AoA34']}, UseBlCm {settings['UseBlCm']}",
        f"Inflow: steady, uniform (shear exponent {args.shear:g}), aligned with the shaft (tilt {args.tilt:g} deg, "
        "yaw 0); " + (f"blades bent downwind along their first flap mode, tip {args.flap_deflection:g} m, at "
                      "constant length;" if args.flap_deflection else "rigid blades;"),
        f"  precone {geo['PreCone(1)']:g} deg, hub radius {geo['HubRad']:g} m, tip radius {geo['TipRad']:g} m, "
        f"overhang {geo['OverHang']:g} m, tower top {geo['TowerHt']:g} m (AeroDyn tower)",
        f"Each point: {args.rpm:g} rpm, V = Omega R / lambda, DT {inp['env']['DT']:g} s, {args.revs} revolutions "
        "from the initial state, mean of the last one;",
        f"  change from the revolution before: max |dCt| {np.abs(d_ct).max():.1e}, max |dCq| "
        f"{np.abs(d_cq).max():.1e}; driver warnings at {len(warned)} of {cp.size} points",
        f"Ct = RtAeroFxh / (q pi R^2), Cq = RtAeroMxh / (q pi R^3), Cp = Cq lambda, R = {geo['TipRad']:g} m, "
        f"rho = {inp['env']['AirDens']:g} kg/m^3, q = rho V^2 / 2",
        f"z-axis value {NOMINAL_WIND} m/s is nominal (single-table polars: no dependence on the wind speed)",
        f"max Cp {cp[k]:.4f} at lambda {tsr[k[0]]:g}, blade pitch {pitch[k[1]]:g} deg; "
        f"driver run time {seconds / 60:.1f} min (one core)",
    ]
    if tsr.max() >= 11.5 and pitch.min() <= -3.0:
        header[-1:-1] = [
            "lambda >= 11.5 at blade pitch <= -3 deg: AeroDyn's BEMT changes solution branch (Ct irregular by a few %,",
            "  also with UA off); kept as computed (outside the controller's range)"]
    text = format_table(tsr, pitch, cp, ct, cq, header)
    out = Path(args.out)
    out.write_text(text)
    back = read_table(out)
    for name, m in (("cp", cp), ("ct", ct), ("cq", cq)):
        if back[name].shape != m.shape or np.max(np.abs(back[name] - m)) > 6e-7:
            raise RuntimeError(f"{out}: {name} does not read back")
    print(f"wrote {out} ({len(tsr)} x {len(pitch)}), reads back with surrogates.aero._read_block")
    return 0


if __name__ == "__main__":
    sys.exit(main())

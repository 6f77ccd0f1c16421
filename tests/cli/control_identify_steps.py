"""`lash identify-steps` on stepped-current data generated here with numpy (an implementation
independent of lash's): input deadzone, exact ZOH first-order lag, bias, Gaussian noise and the
uint16 duty-cycle sensor code of docs/method.md §B1. Every parameter must come back within 3 %, for the
thesis's values and for others. Bad input exits 2 naming the file/column."""
import json, os, shutil, subprocess, sys, tempfile
import numpy as np

lash = os.environ["LASH"]


def record(dz, K, tau, bias, sigma, dt, dwell, levels, seed):
    rng = np.random.default_rng(seed)
    n = int(round(dwell / dt))
    cur = np.repeat(np.asarray(levels, float), n)
    a = np.exp(-dt / tau)
    z = np.where(cur > dz, cur - dz, 0.0)
    w = np.zeros_like(cur)
    for k in range(1, len(cur)):
        w[k] = a * w[k - 1] + K * (1 - a) * z[k - 1]
    p = bias + w + sigma * rng.standard_normal(len(cur))
    raw = np.clip(np.round((p / 48.82 + 5.98) * 65535 / 100), 0, 65535)
    p_meas = (raw * 100 / 65535 - 5.98) * 48.82
    t = np.arange(len(cur)) * dt
    return t, cur, p_meas


cases = [
    dict(dz=288.0, K=2.15, tau=0.07, bias=90.1, sigma=7.28, dt=0.005, dwell=1.5, seed=1,
         levels=[0, 150, 350, 500, 0, 700, 900, 400, 1100, 0, 1300, 600, 1500, 200, 0, 800, 1000, 1200, 1700, 0]),
    dict(dz=210.0, K=2.9, tau=0.1, bias=60.0, sigma=5.0, dt=0.004, dwell=2.0, seed=2,
         levels=[0, 100, 300, 600, 0, 800, 1000, 450, 1200, 0, 1400, 700, 250, 0, 900, 1100, 0]),
]
with tempfile.TemporaryDirectory() as d:
    for c in cases:
        t, cur, p = record(c["dz"], c["K"], c["tau"], c["bias"], c["sigma"], c["dt"], c["dwell"], c["levels"], c["seed"])
        path = os.path.join(d, "steps.csv")
        with open(path, "w") as f:
            f.write("time_s,i,pressure\n")
            for row in zip(t, cur, p):
                f.write("%r,%r,%r\n" % tuple(float(x) for x in row))
        out = subprocess.run([lash, "identify-steps", path, "--json", "--time-column", "time_s", "--current-column", "i",
                              "--pressure-column", "pressure"], check=True, capture_output=True, text=True).stdout
        j = json.loads(out)
        truth = {"bias_kPa": c["bias"], "deadzone_mA": c["dz"], "gain_kPa_per_mA": c["K"], "tau_s": c["tau"],
                 "noise_sigma_kPa": c["sigma"]}
        for k, v in truth.items():
            rel = (j[k] - v) / v
            print(f"{k}: truth {v} fit {j[k]:.6g} rel err {rel:+.2e}")
            assert abs(rel) <= 0.03, (k, v, j[k])
    # The table form and the plot.
    table = subprocess.run([lash, "identify-steps", path, "--time-column", "time_s", "--current-column", "i",
                            "--pressure-column", "pressure"], check=True, capture_output=True, text=True).stdout
    assert "deadzone" in table and "x-intercept" in table, table
    if shutil.which("gnuplot"):
        png = os.path.join(d, "fit.png")
        subprocess.run([lash, "identify-steps", path, "--time-column", "time_s", "--current-column", "i",
                        "--pressure-column", "pressure", "--plot", png], check=True, capture_output=True)
        assert open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    # Bad input: unknown column → exit 2 naming it; no zero-current data → exit 2.
    r = subprocess.run([lash, "identify-steps", path, "--json"], capture_output=True, text=True)
    assert r.returncode == 2 and "'t'" in r.stderr and "steps.csv:1" in r.stderr, (r.returncode, r.stderr)
    bad = os.path.join(d, "bad.csv")
    with open(bad, "w") as f:
        f.write("t,current_mA,pressure_kPa\n" + "".join(f"{k*0.005},{500 + 100*(k//200)},{k}\n" for k in range(800)))
    r = subprocess.run([lash, "identify-steps", bad], capture_output=True, text=True)
    assert r.returncode == 2 and "zero-current" in r.stderr, (r.returncode, r.stderr)
print("ok")

"""The linear part of `lash simulate` against an outside oracle: scipy.signal.lfilter.

G(z) = b1/(z + a1)  <=>  lfilter(b=[0, b1], a=[1, a1]); the randomized input and the
sine input are read back from lash's own CSV so both filter the same numbers.
Agreement must be 1e-12 relative (to max |y|)."""
import os, subprocess, sys, tempfile
import numpy as np
from scipy.signal import lfilter

lash = os.environ["LASH"]
with tempfile.TemporaryDirectory() as d:
    plant = os.path.join(d, "g.toml")
    with open(plant, "w") as f:
        f.write('dt = 0.002\n[[blocks]]\nkind = "linear"\na1 = -0.987\nb1 = 0.0421\n')
    worst = 0.0
    for args in (["--input", "randomized", "--seed", "5"],
                 ["--input", "sine", "--amplitude", "600", "--frequency", "3"],
                 ["--input", "square", "--amplitude", "8", "--frequency", "2"]):
        out = os.path.join(d, "o.csv")
        subprocess.run([lash, "simulate", plant, *args, "--duration", "30", "-o", out], check=True)
        data = np.genfromtxt(out, delimiter=",", names=True)
        y_ref = lfilter([0.0, 0.0421], [1.0, -0.987], data["v"])
        err = np.max(np.abs(data["y"] - y_ref)) / np.max(np.abs(y_ref))
        print(f"{args[1]}: samples={len(y_ref)} max rel err={err:.3e}")
        worst = max(worst, err)
    sys.exit(0 if worst <= 1e-12 else 1)

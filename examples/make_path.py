"""A smooth test path for a 6-joint arm: q_i(t) = a_i sin(w_i t), with its exact velocities and
accelerations, as a trajectory CSV (t, q1..q6, qd1..qd6, qdd1..qdd6) on standard output.

    python examples/make_path.py SECONDS RATE_HZ > path.csv

examples/puma560-path.csv is `python examples/make_path.py 0.25 1000` (the README's lookahead
commands use it).
"""
import sys

import numpy as np

# rad: within the Puma 560's position limits but for the elbow's 0.8, which passes its upper limit of
# 0.785 rad where sin(4 t) > 0.98, from t = 0.35 s: longer paths leave the limits there (vampc lookahead
# refuses them, naming the line, unless --allow-out-of-limits; the 0.25 s example stays within)
AMPLITUDE = np.array([1.0, 0.6, 0.8, 1.0, 0.7, 1.0])
OMEGA = np.array([3.0, 2.5, 4.0, 5.0, 6.0, 7.0])         # rad/s


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    seconds, rate = float(sys.argv[1]), float(sys.argv[2])
    t = np.arange(int(round(seconds * rate))) / rate
    phase = np.outer(t, OMEGA)
    q = AMPLITUDE * np.sin(phase)
    qd = AMPLITUDE * OMEGA * np.cos(phase)
    qdd = -AMPLITUDE * OMEGA ** 2 * np.sin(phase)
    head = ",".join(["t"] + [f"{p}{i}" for p in ("q", "qd", "qdd") for i in range(1, 7)])
    np.savetxt(sys.stdout, np.column_stack([t, q, qd, qdd]), delimiter=",", header=head, comments="",
               fmt="%.17g")
    return 0


if __name__ == "__main__":
    sys.exit(main())

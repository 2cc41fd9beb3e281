"""The same bits on every machine: a robot's constants, the host's A_i(q) and so the torques do not
depend on which BLAS kernel NumPy's `@` would call (README, *Same bits on every machine*).

Two checks, each independent of the code under test: the products against Python's own float
arithmetic in the order vampc.robot.chain.matmul defines (each product and sum rounded on its own:
Python never fuses a multiply-add), and whole runs (compile and emulate, in-process) under
OpenBLAS's Sandy Bridge kernel, which rounds every multiply-add in two steps where this machine's
Haswell kernel fuses them, against the same runs under the default kernel. Before 2026-12-07 the
second gave other program files and torques for examples/arm6.urdf."""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vampc
from vampc.robot.chain import Joint, JointType, matmul, matvec, rot_x, rot_z

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

# a tree of general <origin> turns and joint axes (l1 carries two branches, j2-j3 and j4-j6), to
# take with --floating-base: its joint frames (pre, shift), each Φ and p*, and its base body's
# inertia are sums of inexact products
GENERAL_TREE = """<robot name="tree">
  <link name="base"><inertial><origin xyz="0.01 0.02 0.03" rpy="0.3 0.2 0.1"/><mass value="3"/>
    <inertia ixx="0.1" ixy="0.01" ixz="0.002" iyy="0.12" iyz="0.003" izz="0.15"/></inertial></link>
""" + "".join(f"""  <link name="l{k}"><inertial><origin xyz="0.05 {0.01 * k} -0.02" rpy="{0.1 * k} 0.4 0.7"/>
    <mass value="{1 + 0.3 * k}"/><inertia ixx="0.02" ixy="0.001" ixz="0.0" iyy="0.03" iyz="0.002" izz="0.04"/>
    </inertial></link>
  <joint name="j{k}" type="revolute"><parent link="{"base" if k == 1 else "l1" if k == 4 else f"l{k - 1}"}"/><child link="l{k}"/>
    <origin xyz="0.1 {0.03 * k} 0.2" rpy="{0.37 * k} {0.5 - 0.11 * k} {0.23 * k}"/>
    <axis xyz="{0.2 * k} 1 0.3"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
""" for k in range(1, 7)) + "</robot>\n"

# a MuJoCo arm with turned bodies (quaternions) and joints off the body origins
GENERAL_MJCF = """<mujoco model="arm"><option gravity="0.5 -0.3 -9.7"/><worldbody>
<body name="a" pos="0 0 0.3" quat="0.9 0.1 0.2 0.1"><joint name="j1" type="hinge" axis="0 0.3 1" pos="0.01 0 0"/>
 <inertial pos="0.05 0.01 0" mass="1" diaginertia="0.01 0.02 0.025" quat="0.8 0.2 0.1 0"/>
 <body name="b" pos="0.05 0 0.1" quat="0.7 0.3 -0.2 0.4"><joint name="j2" type="hinge" axis="0.2 1 0"/>
  <inertial pos="0.02 0 0.01" mass="0.8" diaginertia="0.01 0.015 0.02" quat="0.6 0.1 0.3 0.2"/>
  <body name="c" pos="0.3 0.02 0" quat="0.9 -0.1 0.3 0.2"><joint name="j3" type="hinge" axis="1 0.4 0.1" pos="0 0.02 0"/>
   <inertial pos="0.1 0 0" mass="0.5" diaginertia="0.005 0.006 0.007"/></body></body></body>
</worldbody></mujoco>
"""


def _python_product(a, b) -> list:
    """a @ b for one pair of matrices (nested lists of floats), in Python floats, k in order."""
    out = []
    for row in a:
        entries = []
        for j in range(len(b[0])):
            total = row[0] * b[0][j]
            for k in range(1, len(b)):
                total = total + row[k] * b[k][j]
            entries.append(total)
        out.append(entries)
    return out


def test_matmul_is_pythons_arithmetic_in_order():
    rng = np.random.default_rng(7)
    for shape_a, shape_b in (((50, 3, 3), (3, 3)), ((3, 3), (50, 3, 3)), ((50, 4, 4), (50, 4, 4)),
                             ((50, 3, 3), (50, 3, 1)), ((2, 5), (5, 3))):
        a, b = rng.normal(size=shape_a), rng.normal(size=shape_b)
        got = matmul(a, b)
        stack_a = np.broadcast_to(a, got.shape[:-2] + a.shape[-2:]).reshape(-1, *a.shape[-2:])
        stack_b = np.broadcast_to(b, got.shape[:-2] + b.shape[-2:]).reshape(-1, *b.shape[-2:])
        want = np.array([_python_product(x.tolist(), y.tolist()) for x, y in zip(stack_a, stack_b)])
        assert got.reshape(want.shape).tobytes() == want.tobytes(), (shape_a, shape_b)
    # three factors: left to right, as `@` chains them
    a, b, c = (rng.normal(size=(3, 3)) for _ in range(3))
    assert matmul(a, b, c).tobytes() == np.array(_python_product(_python_product(a.tolist(), b.tolist()),
                                                                 c.tolist())).tobytes()
    v = rng.normal(size=3)
    assert matvec(a, v).tobytes() == np.array([r[0] for r in _python_product(a.tolist(),
                                                                              [[x] for x in v])]).tobytes()


def test_the_hosts_a_of_q_is_pythons_arithmetic_in_order():
    """A_i(q) = Rz(q + offset) Φ_i (then M_d times it), every set: what the host writes to the
    network, the same bits as Python's floats give."""
    rng = np.random.default_rng(3)
    pre = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    q = rng.uniform(-3, 3, size=200)
    q[:8] = [-0.25, -0.25 + np.pi / 2, -0.25 - np.pi, -0.0, 1e300, -1e-300, 5e-324, 0.0]
    # a general Φ, and a DH row's Rx(0) and Rx(π/2), whose entries include -0.0 and 6e-17
    for phi in (np.linalg.qr(rng.normal(size=(3, 3)))[0], rot_x(0.0), rot_x(np.pi / 2)):
        for joint_pre in (None, pre):
            joint = Joint(name="j", type=JointType.REVOLUTE, phi=phi, p_fixed=np.zeros(3), offset=0.25,
                          mass=1.0, com=np.zeros(3), inertia=np.eye(3), pre=joint_pre)
            got = joint.A(q)
            turns = rot_z(q + 0.25)
            want = [_python_product(t.tolist(), phi.tolist()) for t in turns]
            if joint_pre is not None:
                want = [_python_product(pre.tolist(), w) for w in want]
            assert got.tobytes() == np.array(want).tobytes()


CHILD = """
import hashlib, json, os, sys
import numpy as np
from click.testing import CliRunner
from vampc.cli import main
os.environ["VAMPC_PROGRESS"] = "0"
rng = np.random.default_rng(0)
a = rng.normal(size=(200, 3, 3))
out = {"blas": hashlib.sha256((a @ a).tobytes()).hexdigest()}
runner = CliRunner()
for k, (robot, options) in enumerate(json.loads(sys.argv[1])):
    prog = f"robot{k}.vamp.json"
    res = runner.invoke(main, ["compile", robot, *options, "-o", prog], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    res = runner.invoke(main, ["emulate", prog, "--random", "100", "--seed", "5", "-o", "-"],
                        catch_exceptions=False)
    assert res.exit_code == 0, res.output
    out[robot] = [hashlib.sha256(open(prog, "rb").read()).hexdigest(),
                  hashlib.sha256(res.stdout_bytes).hexdigest()]
print(json.dumps(out))
"""


def _digests(tmp_path, robots, **env) -> dict:
    folder = tmp_path / "_".join(f"{k}-{v}" for k, v in env.items()) if env else tmp_path / "default"
    # (the children start from this environment without its OpenBLAS and NumPy CPU settings)
    folder.mkdir()
    child_env = {k: v for k, v in os.environ.items() if not k.startswith(("OPENBLAS", "NPY_"))}
    child_env.update(env, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(robots)], cwd=folder, env=child_env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1])


def test_programs_and_torques_do_not_depend_on_the_blas_kernel(tmp_path):
    """examples/arm6.urdf and examples/ur5.urdf (chains of general <origin> turns), a tree of such
    turns on a floating base (joint frames pre and shift, the base body's inertia) and a MuJoCo arm
    (where MuJoCo is installed): the program file and 100 sets' torques, byte for byte, under the
    default kernel and under OpenBLAS's Sandy Bridge one (and with NumPy's loops for a CPU without
    AVX2). Under the code before, every program file differed under the two kernels, and every
    robot's torques but ur5's."""
    tree = tmp_path / "tree.urdf"
    tree.write_text(GENERAL_TREE)
    robots = [(str(EXAMPLES / "arm6.urdf"), []), (str(EXAMPLES / "ur5.urdf"), []),
              (str(tree), ["--floating-base"])]
    try:
        import mujoco  # noqa: F401
        arm = tmp_path / "arm.xml"
        arm.write_text(GENERAL_MJCF)
        robots.append((str(arm), []))
    except ImportError:
        pass
    robots = [list(r) for r in robots]
    default = _digests(tmp_path, robots)
    other = _digests(tmp_path, robots, OPENBLAS_CORETYPE="Sandybridge")
    if other["blas"] == default["blas"]:
        pytest.skip("the BLAS kernel could not be changed here (not OpenBLAS on x86-64, or its "
                    "kernels round these products alike)")
    for robot, _ in robots:
        assert other[robot][0] == default[robot][0], f"{robot}: the program file differs"
        assert other[robot][1] == default[robot][1], f"{robot}: the torques differ"
    # and NumPy's own loops at their baseline instead of AVX2 (its sin, cos, sums and products
    # dispatch on the CPU), where this machine has AVX2 to turn off
    # (NumPy 2's module; NumPy 1 knows no X86_V3, so there the check is left out)
    try:
        from numpy._core._multiarray_umath import __cpu_features__
    except ImportError:
        from numpy.core._multiarray_umath import __cpu_features__
    if __cpu_features__.get("X86_V3"):
        plain = _digests(tmp_path, robots, NPY_DISABLE_CPU_FEATURES="X86_V3")
        for robot, _ in robots:
            assert plain[robot] == default[robot], f"{robot}: NumPy's baseline loops differ"


PRECISION_CHILD = """
import hashlib, json, sys
import numpy as np
from click.testing import CliRunner
from vampc.cli import main
rng = np.random.default_rng(0)
a = rng.normal(size=(200, 3, 3))
res = CliRunner().invoke(main, ["precision", sys.argv[1], "--format", "json", "--sets", "1",
                                "--sweep", "19:19"], catch_exceptions=False)
assert res.exit_code == 0, res.output
print(json.dumps({"blas": hashlib.sha256((a @ a).tobytes()).hexdigest(), "out": res.output}))
"""


def test_a_precision_bound_does_not_depend_on_the_blas_kernel(tmp_path):
    """`vampc precision`'s bound under OpenBLAS's Core2 kernel and the default one: the same bytes.
    Its norms went through the BLAS (np.linalg.norm: a dot, LAPACK's SVD), and examples/arm6.urdf's
    bound in q10.9 was 0.3506447868084065 under this machine's default kernel, ...066 under Core2
    (a helper's sweep, 2026-12-07; this test fails on the code before)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OPENBLAS", "NPY_"))}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    said = {}
    for kernel in ("", "Core2"):
        under = {**env, "OPENBLAS_CORETYPE": kernel} if kernel else env
        done = subprocess.run([sys.executable, "-c", PRECISION_CHILD, str(EXAMPLES / "arm6.urdf")],
                              check=False, cwd=tmp_path, capture_output=True, text=True,
                              timeout=300, env=under)
        assert done.returncode == 0, done.stderr[-2000:]
        said[kernel] = json.loads(done.stdout.splitlines()[-1])
    if said[""]["blas"] == said["Core2"]["blas"]:
        pytest.skip("the BLAS kernel could not be changed here (not OpenBLAS on x86-64)")
    row = json.loads(said[""]["out"])["rows"][0]
    assert row["word"] == "q10.9" and row["bound"] > 0
    assert said["Core2"]["out"] == said[""]["out"]


def test_the_bounds_norms_are_lapacks_to_a_few_ulps():
    """vampc.precision's own norms (Python floats in a fixed order) against NumPy's (the BLAS and
    LAPACK's SVD) on random matrices of every kind the graph holds (inertias: symmetric, some with
    two equal moments; general ones; scaled far up and down), and exactly on diagonal ones."""
    from vampc.precision import spectral_norm, vector_norm
    rng = np.random.default_rng(3)
    for k in range(4000):
        turn = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        moments = rng.uniform(0, 1, 3)
        if k % 4 == 1:
            moments[1] = moments[0]
        m = (rng.normal(size=(3, 3)) if k % 4 == 0 else
             rng.normal(size=(3, 3)) * 10.0 ** int(rng.integers(-300, 300)) if k % 4 == 3 else
             turn * moments @ turn.T)
        want = np.linalg.norm(m, 2)
        assert abs(spectral_norm(m) - want) <= 8 * np.spacing(want), m
        v = m[0]                        # (math.hypot: overflows no square, as NumPy's does)
        assert abs(vector_norm(v) - math.hypot(*v)) <= 2 * np.spacing(math.hypot(*v)), v
    for d in ([3.0, -5.0, 2.0], [0.1, 0.2, 0.3], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0],
              [1e-310, 0, 2e-310]):
        assert spectral_norm(np.diag(d)) == max(abs(x) for x in d)
    assert spectral_norm(np.full((3, 3), 1e307)) == np.linalg.norm(np.full((3, 3), 1e307), 2)
    assert vector_norm([3.0, 4.0, 12.0]) == 13.0 and vector_norm([3e300, 4e300]) == 5e300
    assert vector_norm([0.0, -0.0, 0.0]) == 0.0 and vector_norm([1.0, np.inf, 0.0]) == np.inf
    # a NaN is not passed by (max() skips it: a matrix's norm had come out 0.0, a review's find)
    assert math.isnan(vector_norm([np.inf, np.nan])) and math.isnan(vector_norm([1.0, np.nan]))
    assert math.isnan(spectral_norm([[1, np.nan, 0], [0, 1, 0], [0, 0, 1]]))


# Where NumPy's BLAS-backed products may stay in vampc's source: checks to a tolerance and robots
# made up for tests, whose bits reach no program file, host word or torque of a robot file.
ALLOWED = {
    ("robot/chain.py", "m @ m.T"),            # a rotation's check, to 1e-9
    ("robot/random.py", "rot @ np.diag"),     # random test robots
    ("robot/urdf.py", "np.linalg.norm(np.asarray(j.axis"),   # only whether an axis is zero
}
BLAS_CALLS = ("np.dot(", ".dot(", "np.matmul(", "np.einsum(", "np.tensordot(", "np.inner(",
              "np.vdot(")


def test_no_blas_product_reaches_a_program_or_a_torque():
    """The robot loaders, the host, the dataflow graph's constants, the emulator and the program
    writer hold no `@` (but a decorator), np.dot, matmul, einsum or np.linalg.norm of a whole vector
    (a BLAS dot: norm along an axis is NumPy's own sum) outside ALLOWED: what a machine's BLAS
    kernel would round its own way; nor does `vampc precision`, whose bounds are printed and choose
    words. (The reference dynamics, vampc/dynamics, is a check to a tolerance and keeps them.)"""
    import io
    import tokenize
    root = Path(vampc.__file__).resolve().parent
    found = []
    paths = [(f"{folder}/{path.name}", path)
             for folder in ("robot", "dataflow", "emulator", "program", "network", "machine",
                            "schedule")
             for path in sorted((root / folder).glob("*.py"))]
    paths.append(("precision.py", root / "precision.py"))     # (its bounds: printed; words by them)
    for name, path in paths:
        text = path.read_text()
        lines = text.splitlines()
        at_line_start = True
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.OP and tok.string == "@" and not at_line_start:
                found.append((name, tok.start[0]))
            at_line_start = tok.type in (tokenize.NEWLINE, tokenize.NL, tokenize.INDENT,
                                         tokenize.DEDENT, tokenize.COMMENT)
        for number, line in enumerate(lines, 1):
            code = line.split("#")[0]
            if any(call in code for call in BLAS_CALLS) or ("linalg.norm(" in code
                                                            and "axis" not in code):
                found.append((name, number))
    unexplained = [f"{name}:{number}: {(root / name).read_text().splitlines()[number - 1].strip()}"
                   for name, number in found
                   if not any(name == where and snippet in (root / name).read_text().splitlines()[number - 1]
                              for where, snippet in ALLOWED)]
    assert not unexplained, "\n".join(unexplained)


@pytest.mark.parametrize("locks", [("wrist_bend", "shoulder"), ("shoulder", "wrist_bend")])
def test_locked_joints_are_kept_in_the_order_given(tmp_path, locks):
    """The program file's robot.locked lists the --lock joints as the command line gives them: they
    were read from a set, whose order followed PYTHONHASHSEED, so two runs of the same command
    wrote two program files (a helper's sweep under six hash seeds)."""
    from click.testing import CliRunner

    from vampc.cli import main
    prog = tmp_path / "p.vamp.json"
    args = ["compile", str(EXAMPLES / "arm6.urdf"), "-o", str(prog)]
    for name in locks:
        args += ["--lock", f"{name}=0.1"]
    res = CliRunner().invoke(main, args, catch_exceptions=False)
    assert res.exit_code == 0, res.output
    assert json.loads(prog.read_text())["robot"]["locked"] == list(locks)

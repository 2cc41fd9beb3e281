"""Faults injected into the tick engine (vampc.emulator.faults, `vampc emulate --fault`): stuck,
flipped and intermittent bits of Result, operand and control registers, and dead VAMPs, applied to
the bits of the real word; bad fault specs are one-line errors."""
from __future__ import annotations

import struct

import numpy as np
import pytest
from click.testing import CliRunner
from emulator_util import loaded

from vampc.cli import main
from vampc.emulator import emulate
from vampc.emulator.faults import parse_fault, set_bit
from vampc.emulator.host import random_trajectory
from vampc.machine.arith import parse_word
from vampc.robot.random import random_chain

CHAIN = random_chain(3, 4, prismatic_fraction=0.3)
LD = loaded(CHAIN)
TRAJ = random_trajectory(CHAIN, 12, 3)
GOOD = emulate(LD, TRAJ, "tick").tau
P = LD.period


def _run(*specs):
    with np.errstate(all="ignore"):
        return emulate(LD, TRAJ, "tick", faults=[parse_fault(s) for s in specs]).tau


def _uses(v: int):
    """The Data-Mode ticks (set 0) at which VAMP v latches and dumps."""
    s = LD.schedule
    node = LD.net.vamps[v].slots[0].node
    return s.start[node], s.finish[node] - 1


def _changed(tau) -> np.ndarray:
    """Per set: whether its torques differ from the fault-free run (NaN counts as different)."""
    return ~np.all(np.isclose(tau, GOOD, rtol=0, atol=0) & np.isfinite(tau), axis=1)


# bit 62 is a binary64 word's top exponent bit: 1 for |x| >= 2, so stuck at 0 it makes such a
# value tiny (a stuck bit that already holds its stuck value changes nothing: hence "most sets")
STUCK = "stuck=result.z:62,value=0"


def test_a_stuck_high_bit_on_a_result_spoils_the_torques():
    v = LD.net.outputs[0].vamp             # the VAMP τ1 is read from
    tau = _run(f"vamp={v},{STUCK}")
    assert _changed(tau).sum() >= len(tau) // 2


def test_a_fault_starting_later_leaves_the_earlier_sets_alone():
    v = LD.net.outputs[0].vamp
    _, dump = _uses(v)
    at = dump + 1 + 5 * P                   # after set 5's value has been read
    tau = _run(f"vamp={v},{STUCK},at={at}")
    changed = _changed(tau)
    assert not changed[:6].any() and changed[6:].any()
    assert np.array_equal(changed[6:], _changed(_run(f"vamp={v},{STUCK}"))[6:])


def test_a_result_fault_acts_after_the_dumps_of_its_own_tick():
    # README, Faults: "A Result fault acts after the tick's dumps (the register holds it until the
    # next dump)". Starting at the tick set 5 is dumped, it holds set 5's value stuck before anyone
    # reads it; a tick later set 5 has been read. (A fault starting a tick late passed the test above.)
    v = LD.net.outputs[0].vamp
    _, dump = _uses(v)
    assert list(_changed(_run(f"vamp={v},{STUCK},at={dump + 5 * P}")))[:7] == [False] * 5 + [True] * 2
    assert list(_changed(_run(f"vamp={v},{STUCK},at={dump + 5 * P + 1}")))[:7] == [False] * 6 + [True]


def test_a_transient_flip_spoils_one_set():
    # operand B's high bits flipped in the tick a systolic VAMP latches set 4's: that set only
    v = LD.net.outputs[0].vamp
    latch, _ = _uses(v)
    tau = _run(*(f"vamp={v},flip=b.{k}:62,at={latch + 4 * P}" for k in range(3)))
    assert list(np.flatnonzero(_changed(tau))) == [4]


def test_an_intermittent_fault_spoils_some_cycles_and_is_repeatable():
    v = LD.net.outputs[0].vamp
    spec = f"vamp={v},{STUCK},rate=0.5"
    a, b = _run(spec), _run(spec)
    np.testing.assert_array_equal(a, b)
    changed, always = _changed(a), _changed(_run(f"vamp={v},{STUCK}"))
    assert 0 < changed.sum() < always.sum() and not (changed & ~always).any()


def test_an_intermittent_fault_holds_in_about_its_rate_of_cycles():
    """rate=0.1 (not 0.5, which reads the same either way round): a stuck Result bit of the VAMP τ1
    is read from spoils a set only if it holds in the cycle that set is read, so of the sets the
    permanent fault spoils (193 of 200), a binomial 10% ± 2.2% are spoiled when it holds in a tenth
    of the cycles (22, with the engine's seed 3), and never one it leaves alone. (Active where the
    draw was above the rate, it spoiled 171: 89%.)"""
    traj = random_trajectory(CHAIN, 200, 3)
    v = LD.net.outputs[0].vamp
    with np.errstate(all="ignore"):
        good, always, some = (emulate(LD, traj, "tick", seed=3, faults=[parse_fault(s) for s in spec]).tau
                              for spec in ([], [f"vamp={v},{STUCK}"], [f"vamp={v},{STUCK},rate=0.1"]))

    def spoiled(tau):
        return ~np.all((tau == good) & np.isfinite(tau), axis=1)
    assert spoiled(always).sum() > 150 and not (spoiled(some) & ~spoiled(always)).any()
    assert 0.03 < spoiled(some).sum() / spoiled(always).sum() < 0.2


def test_a_dead_vamp_is_seen():
    v = LD.net.outputs[0].vamp
    assert _changed(_run(f"vamp={v},dead")).all()      # its undriven Result: every torque read


def test_a_stuck_control_bit_holds_in_the_register_and_a_wrong_op_is_seen():
    # the slot table holds the stuck bit from the fault's tick on
    from vampc.emulator.host import port_values
    from vampc.emulator.tick import TickEngine
    v = LD.net.outputs[0].vamp
    rom = LD.programs[v][0].rom
    engine = TickEngine(LD, faults=[parse_fault(f"vamp={v},stuck=control.rom:1,value={1 - (rom >> 1 & 1)},at=9")])
    engine.program()
    assert engine.tables[v][0][3] == rom
    with np.errstate(all="ignore"):
        tau = engine.run(port_values(LD, TRAJ), TRAJ.count)
    assert engine.tables[v][0][3] == rom ^ 2
    # another micro-sequence on the VAMP τ1 is read from: the torques change from then on
    assert _changed(tau).any()


@pytest.mark.parametrize("bit", [0, 7, 31, 47, 62, 63])
def test_float64_bits_are_the_ieee_pattern(bit):
    word = parse_word("float64")
    x = np.array([1.2345e3])
    (raw,) = struct.unpack("<Q", struct.pack("<d", x[0]))
    want = struct.unpack("<d", struct.pack("<Q", raw ^ (1 << bit)))[0]
    got = set_bit(word, x, bit, "flip")[0]
    assert got == want or (np.isnan(got) and np.isnan(want))


@pytest.mark.parametrize("bit", [0, 7, 22, 23, 30, 31])
@pytest.mark.parametrize("how", ["flip", "set", "clear"])
def test_float32_bits_are_the_ieee_binary32_pattern(bit, how):
    # README, Faults: "the IEEE binary64 or binary32 pattern"; the oracle is struct's binary32
    word = parse_word("float32")
    for x in (1.2345e3, -3.0e-2, 7.0):
        (raw,) = struct.unpack("<I", struct.pack("<f", x))
        pattern = {"flip": raw ^ (1 << bit), "set": raw | (1 << bit), "clear": raw & ~(1 << bit)}[how]
        want = struct.unpack("<f", struct.pack("<I", pattern))[0]
        got = set_bit(word, np.array([x], dtype=np.float32), bit, how)[0]
        assert got == want or (np.isnan(got) and np.isnan(want)), (x, bit, how)


@pytest.mark.parametrize("fmt,bit", [("q3.8", 0), ("q3.8", 9), ("q3.8", 10), ("q12.20", 31),
                                     ("q32.32", 0), ("q32.32", 31), ("q32.32", 62), ("q32.32", 63),
                                     ("q31.32", 62)])
@pytest.mark.parametrize("how", ["flip", "set", "clear"])
def test_fixed_point_bits_of_every_width_are_twos_complement(fmt, bit, how):
    # the width's own sign bit included (bit 63 of a 64-bit word is int64's sign); the oracle is
    # Python's unbounded integers, not numpy's
    word = parse_word(fmt)
    w = word.bits
    for raw in (-(1 << (w - 1)) + 5, -1, 0, (1 << (w - 2)) + 3, (1 << (w - 1)) - 1):
        u = raw % (1 << w)
        pattern = {"flip": u ^ (1 << bit), "set": u | (1 << bit), "clear": u & ~(1 << bit)}[how]
        want = pattern - (1 << w) if pattern >= 1 << (w - 1) else pattern
        assert int(set_bit(word, np.array([raw], dtype=np.int64), bit, how)[0]) == want, (fmt, raw, bit)


@pytest.mark.parametrize("bit", [0, 5, 16, 30, 31])
def test_fixed_point_bits_are_the_raw_twos_complement_bits(bit):
    word = parse_word("q16.16")                     # 32-bit words held as int64 raw values
    raw = -123_456
    u = raw & 0xFFFFFFFF                            # the 32-bit pattern, by Python's integers
    flipped = u ^ (1 << bit)
    want = flipped - (1 << 32) if flipped >= 1 << 31 else flipped
    assert set_bit(word, np.array([raw], dtype=np.int64), bit, "flip")[0] == want
    assert set_bit(word, np.array([raw], dtype=np.int64), bit, "set")[0] == (
        (u | (1 << bit)) - (1 << 32) if (u | (1 << bit)) >= 1 << 31 else u | (1 << bit))


@pytest.mark.parametrize("spec,says", [
    ("stuck=result.z:3", "give vamp=N"),
    ("vamp=1,stuck=result.z:3,dead", "give one of"),
    ("vamp=1,stuck=result.q:3", "is no register"),
    ("vamp=1,stuck=result.z", "REGISTER:BIT"),
    ("vamp=1,flip=a.x:3", "give at=T"),
    ("vamp=1,stuck=control.rom:1,rate=0.5", "rate= applies"),
    ("vamp=1,flip=a.x:3,at=4,value=1", "value=0 or value=1"),
    ("vamp=1,stuck=b.9:3", "is no register"),
    ("vamp=x,dead", "not a whole number"),
    ("vamp=1,dead,colour=red", "unknown field"),
])
def test_bad_fault_specs_are_usage_errors(spec, says):
    with pytest.raises(ValueError, match=says):
        parse_fault(spec)


def test_faults_on_the_command_line(tmp_path):
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/planar2.yaml", "-o", str(prog)]).exit_code == 0
    res = run(main, ["emulate", str(prog), "--random", "5", "--fault", "vamp=1,dead"])
    assert res.exit_code == 2 and "--fault needs --engine tick" in res.stderr
    res = run(main, ["emulate", str(prog), "--random", "5", "--engine", "tick", "--fault",
                     "vamp=999,dead"])
    assert res.exit_code == 1 and len(res.stderr.splitlines()) == 1
    assert "there is no VAMP 999" in res.stderr
    res = run(main, ["emulate", str(prog), "--random", "5", "--engine", "tick", "--fault",
                     "vamp=0,stuck=result.x:70"])
    assert res.exit_code == 1 and "the register has 64 bits" in res.stderr
    res = run(main, ["emulate", str(prog), "--random", "5", "--engine", "tick", "--fault",
                     "vamp=0,dead,at=100000"])
    assert res.exit_code == 1 and "after the run's last tick" in res.stderr
    res = run(main, ["emulate", str(prog), "--random", "5", "--engine", "tick", "--check",
                     "--fault", "vamp=0,stuck=result.z:62,value=1", "--fault",
                     "vamp=0,stuck=result.y:62,value=1", "--fault", "vamp=0,stuck=result.x:62,value=1"])
    assert res.exit_code == 1          # the spoiled torques do not pass the check, or are refused
    # a torque made infinite or NaN by an injected fault is blamed on the fault, not on the robot
    res = run(main, ["emulate", str(prog), "--random", "5", "--engine", "tick", "--fault",
                     "vamp=10,stuck=result.x:62,value=1"])
    assert res.exit_code == 1 and len(res.stderr.splitlines()) == 1, res.stderr
    assert "float64 overflow under the injected fault)" in res.stderr, res.stderr
    assert "robot's or the state's numbers" not in res.stderr


@pytest.mark.parametrize("specs,says", [
    (("vamp=5,stuck=result.z:62,value=1", "vamp=5,stuck=result.z:62,value=0"), "same bit of VAMP 5"),
    (("vamp=5,dead", "vamp=5,stuck=result.z:62,value=1"), "VAMP 5 is dead from tick 0"),
    (("vamp=5,dead,at=30", "vamp=5,flip=result.z:62,at=30"),
     "so --fault 'vamp=5,flip=result.z:62,at=30' does nothing"),
    (("vamp=5,dead,at=20", "vamp=5,dead,at=10"), "dead from tick 10 (its outputs tri-stated), so "
                                                 "--fault 'vamp=5,dead,at=20' does nothing"),
    (("vamp=5,stuck=a.x:3", "vamp=5,flip=a.0:3,at=4"), "is stuck from tick 0, so a flip at tick 4"),
    (("vamp=5,stuck=result.x:3,value=1,at=2", "vamp=5,stuck=result.x:3,value=1,at=9"),
     "stuck at 1 from tick 2, so --fault 'vamp=5,stuck=result.x:3,value=1,at=9' does nothing"),
    (("vamp=5,stuck=result.x:3", "vamp=5,stuck=result.x:3,value=0,at=0"), "the same fault given twice"),
    (("vamp=5,flip=a.x:3,at=4", "at=4,vamp=5,flip=a.x:3"), "the same fault given twice"),
    (("vamp=5,dead", "vamp=5,dead"), "given twice"),
])
def test_conflicting_faults_are_usage_errors(tmp_path, specs, says):
    """Two faults whose outcome depends on their order (the last given had won in silence: a
    stuck-at 1 and a stuck-at 0 on one bit, a dead VAMP and a stuck bit on it) are refused, naming
    both; faults on other VAMPs or bits, flips of one bit at other ticks, and faults on one bit or
    VAMP at times where the order cannot matter (a stuck bit before the VAMP dies, a flip before
    the bit sticks, the same bit stuck at the same value: a review found these refused) run."""
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/planar2.yaml", "-o", str(prog)]).exit_code == 0
    args = ["emulate", str(prog), "--random", "2", "--engine", "tick", "-o", str(tmp_path / "t.csv")]
    res = run(main, args + [x for spec in specs for x in ("--fault", spec)])
    assert res.exit_code == 2 and len(res.stderr.splitlines()) == 1, res.stderr
    assert says in res.stderr and specs[0] in res.stderr and res.stdout == ""
    assert not (tmp_path / "t.csv").exists()
    for fine in (("vamp=5,stuck=result.z:62,value=1", "vamp=6,stuck=result.z:62,value=0"),
                 ("vamp=5,stuck=result.z:62,value=1", "vamp=5,stuck=result.z:61,value=0"),
                 ("vamp=5,flip=a.x:3,at=4", "vamp=5,flip=a.x:3,at=8"),
                 ("vamp=5,dead,at=20", "vamp=5,stuck=result.x:62,value=1,at=5"),
                 ("vamp=5,flip=result.x:62,at=5", "vamp=5,stuck=result.x:62,value=0,at=20"),
                 ("vamp=5,stuck=result.x:62,value=1,at=2,rate=0.5", "vamp=5,stuck=result.x:62,value=1,at=10")):
        res = run(main, args + [x for spec in fine for x in ("--fault", spec)])
        assert res.exit_code == 0, res.stderr


@pytest.mark.parametrize("pair", [
    ("vamp={v},stuck=result.z:3,value=1,at=0", "vamp={v},dead,at=8"),
    ("vamp={v},stuck=result.z:3,value=1,rate=0.3", "vamp={v},stuck=result.z:3,value=1,at=4,rate=0.7"),
    ("vamp={v},flip=result.z:3,at=2", "vamp={v},stuck=result.z:3,value=0,at=6,rate=0.5"),
    ("vamp={v},dead,at=10", "vamp=30,dead,at=10"),
])
def test_the_order_faults_are_given_in_does_not_change_the_torques(tmp_path, pair):
    """Faults act in one order whatever order they are given in (vampc.emulator.faults.canonical):
    a bit stuck before its VAMP died showed through its tri-stated outputs or not by which came
    last, and intermittent faults and dead VAMPs drew their random cycles and contents by their
    place on the command line (a review's find: 9 to 30 of planar2's 60 VAMPs gave other torques
    with the two swapped)."""
    prog = tmp_path / "p.vamp.json"
    run = CliRunner().invoke
    assert run(main, ["compile", "examples/planar2.yaml", "-o", str(prog)]).exit_code == 0
    for v in (3, 5, 12, 20, 41):
        specs = [p.format(v=v) for p in pair]
        got = []
        for order in (specs, specs[::-1]):
            res = run(main, ["emulate", str(prog), "--random", "4", "--engine", "tick", "-o", "-"]
                      + [x for spec in order for x in ("--fault", spec)])
            assert res.exit_code in (0, 1) and "Traceback" not in res.output, res.output
            got.append(res.stdout)
        assert got[0] == got[1], (v, specs)


def test_every_fault_example_of_the_help_is_taken():
    """`emulate --help` gave `rate=0.1` as a --fault example, which is refused ("give one of
    stuck=REG:BIT, flip=REG:BIT or dead": rate= makes a stuck fault intermittent; an audit's
    find): each example it gives parses."""
    import re
    res = CliRunner().invoke(main, ["emulate", "--help"], terminal_width=1000)
    text = res.output.split("--fault SPEC", 1)[1].split("repeatable", 1)[0]
    examples = re.findall(r"(\S+=\S+) \(", text)
    assert len(examples) == 4, examples
    faults = [parse_fault(spec) for spec in examples]      # (each raises if refused)
    # each the fault it shows: its VAMP, its kind, a rate only where it gives one
    assert [f.kind for f in faults] == ["stuck", "flip", "dead", "stuck"], faults
    for spec, fault in zip(examples, faults):
        assert spec.startswith(f"vamp={fault.vamp},"), (spec, fault)
        assert (fault.rate == 0.1) == ("rate=0.1" in spec), (spec, fault)


def _hand_widths(ld, v: int) -> dict:
    """VAMP v's control fields in bits, worked out here from the machine's description (README,
    Word formats): each delay is compared with the Cycle-Counter, which counts 0..P; the ROM
    pointer picks one of the ROM's 9 entries; a select one of its multiplexer's inputs."""
    import math
    vamp, P = ld.net.vamps[v], ld.period
    counter = math.floor(math.log2(P)) + 1
    return {"delay_a": counter, "delay_b": counter, "delay_r": counter, "rom": 4,
            "sel_a": math.ceil(math.log2(len(vamp.a))), "sel_b": math.ceil(math.log2(len(vamp.b)))}


def test_a_control_fault_reaches_only_the_bits_the_hardware_holds():
    """Faults took every control field as 24 bits, and a random campaign drew bits 0..11 of any
    field: bit 10 of a 3-bit delay, in no register, was a "silent corruption" (a new user's,
    beside the report's and the RTL's counts of the same registers). A bit beyond a field is
    refused, naming its width; a campaign's control bits are each one the hardware has, every
    field's drawn."""
    from vampc.emulator.campaign import faults_of
    from vampc.emulator.faults import check_faults
    from vampc.errors import VampcError
    from vampc.machine.ops import ROM
    from vampc.program.words import FIELDS
    assert len(ROM) == 9
    ld = loaded(CHAIN, layout="folded")        # (P = 40; multiplexers of one to three inputs)
    one = next(v for v, vamp in enumerate(ld.net.vamps) if len(vamp.a) == len(vamp.b) == 1)
    many = next(v for v, vamp in enumerate(ld.net.vamps) if len(vamp.a) == 3 and len(vamp.b) == 2)
    assert _hand_widths(ld, many) == dict(delay_a=6, delay_b=6, delay_r=6, rom=4, sel_a=2, sel_b=1)
    for v in (one, many):
        for field, bits in _hand_widths(ld, v).items():
            if bits:
                check_faults([parse_fault(f"vamp={v},stuck=control.{field}:{bits - 1}")], ld, 100)
            with pytest.raises(VampcError) as refused:
                check_faults([parse_fault(f"vamp={v},stuck=control.{field}:{bits}")], ld, 100)
            held = (f"no bits: VAMP {v}'s {field[-1].upper()} multiplexer has one input, nothing "
                    "to select" if not bits else f"{bits} bit{'s' * (bits > 1)} (0..{bits - 1})")
            assert str(refused.value) == (f"--fault 'vamp={v},stuck=control.{field}:{bits}': bit "
                                          f"{bits}: {field} has {held}, as the hardware holds it "
                                          "(README, Faults)")
    drawn = faults_of(ld, "random", kinds=("control",), count=600, seed=1, sets=12)
    fields = set()
    for f in drawn:
        assert f.register == "control" and f.bit < _hand_widths(ld, f.vamp)[FIELDS[f.component]], f.text
        fields.add(FIELDS[f.component])
    assert fields == set(FIELDS)

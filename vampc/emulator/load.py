"""Loading a program file into the emulator's state description.

The programs the emulator runs are those the Program-Mode stream delivers: a VAMP latches the last word
carrying its number among the words written to the root of its Operand-A path (vampc.program.emit). The
file's `programs` section is a readable listing; it must agree with the stream.
"""
from __future__ import annotations

from dataclasses import dataclass

from vampc.errors import VampcError
from vampc.gcpause import gc_paused
from vampc.network.model import Network, Tap
from vampc.program.document import chain_from_doc, network_from_doc
from vampc.program.emit import a_roots
from vampc.program.file import read_program
from vampc.program.words import ROM, Program, decode
from vampc.robot.chain import Chain


@dataclass(frozen=True)
class Loaded:
    """A program file ready to emulate."""

    path: str
    doc: dict
    chain: Chain
    net: Network                     # wiring (taps); timing fields are not used by the engines
    numbers: tuple[int, ...]         # burned-in VAMP numbers, by logical index
    stream: tuple[tuple[Tap, tuple[tuple[float, float, float], ...]], ...]   # (root, words)
    programs: tuple[Program, ...]    # what Program Mode delivers to each VAMP

    @property
    def cycle(self) -> int:
        """The basic cycle C in ticks."""
        return self.net.cycle

    def vamp_name(self, index: int) -> str:
        """'VAMP 12 (number 13, bwd2.T4)': how messages name a VAMP."""
        node = self.doc["graph"]["nodes"][self.net.vamps[index].node]
        return f"VAMP {index} (number {self.numbers[index]}, {node['section']}{node['group']}.{node['name']})"


def load_program(path: str) -> Loaded:
    """Read, validate and decode a program file."""
    doc = read_program(path)
    return loaded_from_doc(doc, str(path))


@gc_paused()
def loaded_from_doc(doc: dict, path: str = "<program>") -> Loaded:
    """Decode an already-validated document (tests corrupt documents and call this directly)."""
    sched = doc["schedule"]
    if (sched["mult_latency"], sched["add_latency"]) != (1, 1):
        raise VampcError(f"{path}: compiled with --mult-latency {sched['mult_latency']} "
                         f"--add-latency {sched['add_latency']}; the emulated VAMP runs one micro-step "
                         "per tick (1 Mult = 1 Addn = 1 flop, the paper's model): recompile with the "
                         "default latencies to emulate")
    net = network_from_doc(doc)
    numbers = tuple(v["number"] for v in doc["network"]["vamps"])
    _check_indices(doc, net, path)
    stream = tuple((Tap(e["root"][0], e["root"][1]), tuple(tuple(w) for w in e["words"]))
                   for e in doc["program_stream"])
    progs = delivered_programs(net, numbers, stream, path)
    _check_listing(doc, progs, path)
    return Loaded(path, doc, chain_from_doc(doc["robot"]), net, numbers, stream, progs)


def delivered_programs(net: Network, numbers, stream, path) -> tuple[Program, ...]:
    """The program each VAMP latches in Program Mode; VampcError if one gets none or a bad one."""
    # A VAMP sees every word of its root's stream and keeps the last one carrying its number.
    last_word = {root: {_number(w): w for w in words} for root, words in stream}
    progs = []
    roots = a_roots(net)
    for v in net.vamps:
        root, _ = roots[v.index]
        word = last_word.get(root, {}).get(numbers[v.index])
        if word is None:
            raise VampcError(f"{path}: VAMP {v.index} (number {numbers[v.index]}) is never "
                             f"programmed: no word written to {root} carries its number")
        number, prog = decode(word)
        if prog.rom >= len(ROM):
            raise VampcError(f"{path}: VAMP {v.index} (number {number}): ROM pointer {prog.rom} "
                             f"is not in the ROM (0..{len(ROM) - 1})")
        progs.append(prog)
    _check_unclaimed(net, numbers, stream, roots, path)
    return tuple(progs)


def _check_listing(doc, progs, path) -> None:
    """The readable `programs` section must say what the stream delivers."""
    for row, prog in zip(doc["programs"], progs):
        listed = (row["delay_a"], row["delay_b"], row["delay_r"], row["rom"])
        if listed != (prog.delay_a, prog.delay_b, prog.delay_r, prog.rom):
            raise VampcError(f"{path}: programs[{row['vamp']}] lists {listed} (delay-A, delay-B, "
                             f"delay-R, ROM) but the program stream delivers "
                             f"{(prog.delay_a, prog.delay_b, prog.delay_r, prog.rom)}")


def _number(word) -> int:
    return int(word[0]) if float(word[0]).is_integer() else -1


def _check_unclaimed(net, numbers, stream, roots, path) -> None:
    """A word whose number no VAMP on that root's paths carries is a damaged stream."""
    reach: dict[Tap, set[int]] = {}
    for v in net.vamps:
        reach.setdefault(roots[v.index][0], set()).add(numbers[v.index])
    for root, words in stream:
        for k, w in enumerate(words):
            if _number(w) not in reach.get(root, set()):
                raise VampcError(f"{path}: program stream of {root}, word {k}: number {w[0]:g} "
                                 "matches no VAMP on that input's Operand-A paths")


def _check_indices(doc, net: Network, path) -> None:
    """Taps must name existing VAMPs, buffers, stages, ports and constants."""
    sizes = {"vamp": len(net.vamps), "buffer": len(net.buffers), "port": len(net.ports),
             "const": len(net.consts)}
    for v in net.vamps:
        for name, operand in (("A", v.a), ("B", v.b)):
            for tap in operand.taps:
                bad = not tap.index < sizes[tap.kind] or (
                    tap.kind == "buffer" and not 1 <= tap.stage <= net.buffers[tap.index].stages)
                if bad:
                    raise VampcError(f"{path}: VAMP {v.index}: operand {name} is wired to a "
                                     f"missing {tap}")
    if len(set(v["number"] for v in doc["network"]["vamps"])) != len(net.vamps):
        raise VampcError(f"{path}: two VAMPs share a number")
    for b in net.buffers:
        if b.source >= len(net.vamps):
            raise VampcError(f"{path}: buffer {b.index} is fed by missing VAMP {b.source}")

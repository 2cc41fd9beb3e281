"""The machine itself, below every stage that uses it (README, *Extending vampc*): the op table
(each op's micro-steps and latency shape, as data: vampc.machine.ops), the arithmetic interface
(word formats: vampc.machine.arith) and the numpy interpreter of the op table every Python engine
runs (vampc.machine.interp)."""

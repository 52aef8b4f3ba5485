"""Stop signals: a serial run stops at once (outside the writing of a step's files); a distributed run records
the signal and stops every rank together where they all call ``poll`` (solvers/signals.py)."""

from __future__ import annotations

import os
import signal

import pytest

from covcontact.solvers.signals import Interrupted, StopSignals


class FakeComm:
    """Two ranks; the other one has received ``other`` (or nothing)."""

    def __init__(self, other=None):
        self.other = other
        self.calls = 0

    def Get_size(self):
        return 2

    def allgather(self, value):
        self.calls += 1
        return [value, self.other]


def test_serial_stops_at_once_but_not_inside_a_critical_block():
    with StopSignals() as stops:
        with pytest.raises(Interrupted) as info:
            os.kill(os.getpid(), signal.SIGTERM)
        assert info.value.exit_code == 143
        with pytest.raises(Interrupted) as info, stops.critical():
            os.kill(os.getpid(), signal.SIGINT)
            done = True  # the block runs to its end
        assert done and info.value.exit_code == 130
        stops.poll()  # serial: nothing to agree on


def test_distributed_records_and_stops_every_rank_at_poll():
    comm = FakeComm()
    with StopSignals(comm=comm) as stops:
        stops.poll()  # nothing received anywhere
        os.kill(os.getpid(), signal.SIGTERM)  # recorded, not raised
        with stops.critical():
            pass  # nor at the end of a critical block
        with pytest.raises(Interrupted) as info:
            stops.poll()
        assert info.value.exit_code == 143 and comm.calls == 2
        stops.poll()  # acted on once


def test_distributed_stops_when_another_rank_was_signalled():
    with StopSignals(comm=FakeComm(other=int(signal.SIGINT))) as stops, pytest.raises(Interrupted) as info:
        stops.poll()
    assert info.value.exit_code == 130


@pytest.mark.parametrize(("relayed", "code"), [(signal.SIGUSR1, 143), (signal.SIGUSR2, 130)])
def test_distributed_takes_the_signals_mpiexec_relays(relayed, code):
    """Open MPI's mpiexec kills its ranks right after relaying SIGTERM/SIGINT, so ``--ranks`` sends it SIGUSR1 /
    SIGUSR2, which it relays alone; a distributed run takes them as SIGTERM / SIGINT."""
    with StopSignals(comm=FakeComm()) as stops:
        os.kill(os.getpid(), relayed)
        with pytest.raises(Interrupted) as info:
            stops.poll()
    assert info.value.exit_code == code
    assert signal.getsignal(relayed) == signal.SIG_DFL  # handlers restored


def test_one_rank_is_serial():
    class One(FakeComm):
        def Get_size(self):
            return 1

    with StopSignals(comm=One()) as stops:
        assert stops.comm is None
        with pytest.raises(Interrupted):
            os.kill(os.getpid(), signal.SIGTERM)

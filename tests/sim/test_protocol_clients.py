"""tmsim/protocol/clients.py: the connection table with the receive buffers the Listen node protocol and the
control channel protocol share."""
from dataclasses import dataclass, field

import pytest

from tmsim.protocol.clients import Clients
from tmsim.protocol.control import ControlProtocol
from tmsim.protocol.listen_protocol import ListenProtocol
from tmsim.tmscript.work import WorkMeter


@dataclass
class _Record:
    rbuf: bytearray = field(default_factory=bytearray)


def test_received_bytes_go_to_their_connection_and_are_counted():
    clients: Clients[_Record] = Clients()
    clients[1], clients[2] = _Record(), _Record()
    clients.buffer_data(1, b"abc")
    clients.buffer_data(1, b"de")
    clients.buffer_data(2, b"x")
    assert clients[1].rbuf == b"abcde" and clients.input_bytes(1) == 5
    assert clients[2].rbuf == b"x" and clients.input_bytes(2) == 1


def test_bytes_of_an_unknown_connection_are_ignored_and_count_zero():
    clients: Clients[_Record] = Clients()
    clients.buffer_data(7, b"late bytes of a closed client")
    assert 7 not in clients and clients.input_bytes(7) == 0
    clients[7] = _Record()
    del clients[7]
    clients.buffer_data(7, b"more")
    assert clients.input_bytes(7) == 0 and dict(clients) == {}


class _Node:
    """A Listen node that handles nothing: the protocol only buffers what it gets."""

    def __init__(self):
        self.now, self.meter, self.waiting_scripts = 0.0, WorkMeter(), 0

    def handle(self, conn, item):
        raise AssertionError("nothing is decoded in these tests")


def _control() -> ControlProtocol:
    return ControlProtocol(lambda kind, **fields: None)


def _listen() -> ListenProtocol:
    return ListenProtocol(_Node(), lambda kind, **fields: None)


@pytest.mark.parametrize(("make", "partial"), [(_control, b'{"cmd": "pi'), (_listen, b"$TMSCT,")],
                         ids=["control channel: a partial line", "Listen node: a partial frame"])
def test_each_protocol_keeps_what_it_received_in_its_clients(make, partial):
    protocol = make()
    protocol.connect(3)
    protocol.receive_data(3, partial)
    assert isinstance(protocol.clients, Clients)
    assert protocol.input_bytes(3) == len(partial) and protocol.clients[3].rbuf == partial
    protocol.receive_data(4, b"unknown connection")
    assert protocol.input_bytes(4) == 0 and set(protocol.clients) == {3}

"""The connections of one sans-I/O protocol and their receive buffers (``Clients``).

A protocol keeps one state record per connection number; each record holds ``rbuf``, the bytes received from
that connection and not processed yet. ``Clients`` is the table of those records that the Listen node protocol
(tmsim/protocol/listen_protocol.py) and the control channel protocol (tmsim/protocol/control.py) each hold:
it adds received bytes to the right buffer and tells how many wait, ignoring connections it does not know (a
socket read can still deliver bytes of a client the protocol has just ended). It knows nothing else of the
records: outboxes, turns and limits stay with each protocol.
"""
from __future__ import annotations

from typing import Protocol, TypeVar


class Buffered(Protocol):
    """A connection's state record: what ``Clients`` reads and extends of it."""
    rbuf: bytearray                     # bytes received and not processed yet


C = TypeVar("C", bound=Buffered)


class Clients(dict[int, C]):
    """Connection number -> its state record, with the receive buffer calls both protocols share."""

    def buffer_data(self, conn: int, data: bytes) -> None:
        """Bytes received from connection ``conn``, kept in its receive buffer (unknown connection: ignored)."""
        client = self.get(conn)
        if client is not None:
            client.rbuf += data

    def input_bytes(self, conn: int) -> int:
        """Bytes of connection ``conn`` received and not processed yet (0 for an unknown connection)."""
        client = self.get(conn)
        return 0 if client is None else len(client.rbuf)

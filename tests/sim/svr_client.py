"""Requests to the simulator's Ethernet Slave (TMSVR, TMflow 2.24 manual §17.4) over a tests/sim Harness peer:
``ask`` sends one request and returns its one reply, ``values`` reads items in string mode and parses them."""
from tmsim.protocol import codec
from tmsim.protocol import svr_table as table
from tmsim.protocol.svr_table import ITEMS


def svr(data):
    return codec.encode("TMSVR", data)


def ask(h, peer, data):
    """One request (its DATA), its one reply as (header, data bytes)."""
    start = len(peer.frames)
    peer.send(svr(data))
    assert h.until(lambda: len(peer.frames) > start, timeout=2), "the Ethernet Slave did not answer"
    frame = peer.frames[start]
    return frame.header, frame.data


def values(h, peer, names):
    header, data = ask(h, peer, "R1,12," + "\r\n".join(names))
    assert header == "TMSVR" and data.startswith(b"R1,12,"), data
    out = {}
    for line in data[6:].decode().split("\r\n"):
        name, _, text = line.partition("=")
        out[name] = table.parse_string_value(ITEMS[name], text)
    return out

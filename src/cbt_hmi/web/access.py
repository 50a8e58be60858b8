"""Who may do what on the web HMI: access keys, roles and the same-origin rules for writes.

Threat model (docs/hmi.md, "Access control"): the HMI runs in the operator's own browser, so any other page
open in that browser can send requests to it. A write must therefore prove three things:

1. it comes from the HMI's own page: the ``Host`` header names this server (defeats DNS rebinding), an
   ``Origin`` or ``Sec-Fetch-Site`` header, when the browser sends one, is this server's own origin;
2. it is a JSON request with the access-key header, which a cross-site page can only send after a CORS
   preflight, and the server answers no preflight (forms and ``text/plain`` fetches are refused with 415);
3. it carries the key of a role allowed to change that variable. Two keys are made at every start:
   *operator* (run commands) and *engineer* (also the robot address, base, tool, I/O assignment). Without
   a key the HMI is a read-only monitor.
"""
from __future__ import annotations

import hmac
import ipaddress
import secrets
import socket
from http import HTTPStatus

KEY_HEADER = "X-HMI-Key"
ROLES = ("monitor", "operator", "engineer")          # each role may do what the ones before it may
LOOPBACK_NAMES = ("localhost", "127.0.0.1", "[::1]")
WILDCARD_HOSTS = ("0.0.0.0", "::", "")               # binds that listen on every address of the machine


class AccessDenied(Exception):
    """A request refused for who sent it or how; str() is the message, status the HTTP answer."""

    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.FORBIDDEN):
        super().__init__(message)
        self.status = status


def new_key() -> str:
    return secrets.token_urlsafe(18)


def role_at_least(role: str, needed: str) -> bool:
    return ROLES.index(role) >= ROLES.index(needed)


class AccessPolicy:
    """The keys of one HMI server start and the checks every request passes."""

    def __init__(self, operator_key: str | None = None, engineer_key: str | None = None):
        self.keys = {"operator": operator_key or new_key(), "engineer": engineer_key or new_key()}
        if self.keys["operator"] == self.keys["engineer"]:
            raise ValueError("the operator and the engineer key must differ")
        self.hosts: frozenset[str] = frozenset()      # names a Host header may give, without the port
        self.port: int | None = None
        self.any_address = False                       # bound to every address: any IP literal is this server

    def bind(self, host: str, port: int) -> None:
        """Learn the address the server listens on: only Host headers naming it are served.

        Bound to one address, the Host must be that address (on loopback also localhost, 127.0.0.1, [::1]).
        Bound to every address (0.0.0.0, ::), the Host must be an IP address literal, localhost or this
        machine's own name: a DNS-rebinding page always sends the attacker's host name, which is none of them.
        The port must be the server's in every case."""
        names = {_bracketed(host.lower())}
        try:
            if ipaddress.ip_address(host).is_loopback:
                names |= set(LOOPBACK_NAMES)
        except ValueError:
            pass                                       # a host name: only that name is accepted
        self.any_address = host in WILDCARD_HOSTS
        if self.any_address:
            names = set(LOOPBACK_NAMES) | {name.lower() for name in (socket.gethostname(), socket.getfqdn()) if name}
        self.hosts = frozenset(names)
        self.port = port

    def role_of(self, headers) -> str:
        """The role the request's key grants ('monitor' without a key); a wrong key is refused."""
        given = headers.get(KEY_HEADER)
        if given is None or given == "":
            return "monitor"
        for role in ("engineer", "operator"):
            if hmac.compare_digest(given.encode("utf-8", "replace"), self.keys[role].encode()):
                return role
        raise AccessDenied("the HMI access key is not valid for this server start: open the address printed "
                           "at start-up again", HTTPStatus.UNAUTHORIZED)

    def check_host(self, headers) -> None:
        """Every request, reads included: the Host header must name this server (a rebound DNS name is refused)."""
        if self.port is None:
            raise AccessDenied("the HMI server has not started", HTTPStatus.SERVICE_UNAVAILABLE)
        host = (headers.get("Host") or "").strip().lower()
        name, port = _split_host(host)
        if port != self.port or not (name in self.hosts or (self.any_address and _is_ip_literal(name))):
            example = "127.0.0.1" if self.any_address else min(self.hosts)
            raise AccessDenied(f"requests must be addressed to this HMI ({example}:{self.port}), "
                               f"not to {host or 'an unnamed host'}", HTTPStatus.MISDIRECTED_REQUEST)

    def check_write(self, headers) -> str:
        """A state-changing request: same origin, JSON, and a key; returns the role it grants."""
        origin = headers.get("Origin")
        if origin is not None:
            host = (headers.get("Host") or "").strip().lower()
            if origin.strip().lower() != f"http://{host}":
                raise AccessDenied(f"writes are accepted only from the HMI's own pages, not from {origin}")
        site = headers.get("Sec-Fetch-Site")
        if site is not None and site not in ("same-origin", "none"):
            raise AccessDenied(f"writes are accepted only from the HMI's own pages (request was {site})")
        media = (headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if media != "application/json":
            raise AccessDenied("writes must be sent as application/json", HTTPStatus.UNSUPPORTED_MEDIA_TYPE)
        role = self.role_of(headers)
        if role == "monitor":
            raise AccessDenied("this HMI page is in monitor mode (no access key): open the operator address "
                               "printed at start-up to operate", HTTPStatus.UNAUTHORIZED)
        return role


def _bracketed(host: str) -> str:
    """An IPv6 address as a Host header writes it ([::1]); anything else as it is."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def _split_host(host: str) -> tuple[str, int | None]:
    """(name, port) of a Host header value; the port is 80 when none is given (RFC 9110 §7.2, §4.2.1),
    None when it is not a number."""
    name, colon, port = host.rpartition(":")
    if not colon or name.startswith("[") and not name.endswith("]") or "]" in port:
        return host, 80                                 # no port: "name" or "[::1]"
    return name, int(port) if port.isascii() and port.isdigit() and len(port) <= 5 else None


def _is_ip_literal(name: str) -> bool:
    try:
        ipaddress.ip_address(name[1:-1] if name.startswith("[") and name.endswith("]") else name)
    except ValueError:
        return False
    return name.startswith("[") == (":" in name)       # an IPv6 literal only in brackets, as in a URL

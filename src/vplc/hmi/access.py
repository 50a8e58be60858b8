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
from http import HTTPStatus

KEY_HEADER = "X-HMI-Key"
ROLES = ("monitor", "operator", "engineer")          # each role may do what the ones before it may
LOOPBACK_NAMES = ("localhost", "127.0.0.1", "[::1]")


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
        self.hosts: frozenset[str] = frozenset()

    def bind(self, host: str, port: int) -> None:
        """Learn the address the server listens on: only Host headers naming it are served."""
        names = {f"{host}:{port}"}
        try:
            if ipaddress.ip_address(host).is_loopback:
                names |= {f"{name}:{port}" for name in LOOPBACK_NAMES}
        except ValueError:
            pass                                       # a host name: only that name is accepted
        if host in ("0.0.0.0", "::"):
            names = set()                              # any address: the Host check cannot be exact
        self.hosts = frozenset(names)

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
        """Every request: the Host header must name this server (a rebound DNS name is refused)."""
        if not self.hosts:
            return
        host = (headers.get("Host") or "").strip().lower()
        if host not in self.hosts:
            raise AccessDenied(f"requests must be addressed to this HMI ({sorted(self.hosts)[0]}), "
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

"""A minimal JSON client for the HMI server API (tests only)."""
from __future__ import annotations

import json
import urllib.error
import urllib.request


class Client:
    """Sends the access key of one role (None: no key, the HMI's monitor mode) with every request."""

    def __init__(self, base: str, key: str | None = None):
        self.base = base
        self.key = key

    def request(self, path: str, body=None, raw: bytes | None = None, headers=None):
        data = raw if raw is not None else (None if body is None else json.dumps(body).encode())
        req = urllib.request.Request(self.base + path, data=data, headers=headers or {})
        if self.key is not None and not req.has_header("X-hmi-key"):
            req.add_header("X-HMI-Key", self.key)
        if data is not None and not req.has_header("Content-type"):
            req.add_header("Content-Type", "application/json")
        try:
            with urllib.request.urlopen(req, timeout=5) as resp:
                return resp.status, resp.read(), resp.headers
        except urllib.error.HTTPError as err:
            return err.code, err.read(), err.headers

    def json(self, path: str, body=None, **kw):
        status, payload, _ = self.request(path, body, **kw)
        return status, json.loads(payload)

"""The pages' static files as the panel's browser keeps them (docs/hmi.md, "What the browser keeps").

A file's *version* is a digest of its bytes. The page shell (``index.html``) is never kept: each page change reads it
again, and it names its style sheets, scripts and preloaded data files with their versions (``hmi.js?v=<version>``).
A file asked for with the version its bytes have now may be kept for good (RFC 8246 ``immutable``): a changed file
has another version, so the next shell names another address and the browser reads the new file. Any other file
(asked for without a version, or with an old one) is kept only with its validators, ``ETag`` and ``Last-Modified``:
the browser asks again on every use (RFC 9111 5.2.2.4, ``no-cache``) and gets ``304 Not Modified`` without the bytes
while the file is unchanged (RFC 9110 13.1.2 ``If-None-Match``; 13.1.3 ``If-Modified-Since``, which Chromium sends
to a server answering HTTP/1.0, as this one does)."""
from __future__ import annotations

import email.utils
import hashlib
import pathlib
import re
import time
from dataclasses import dataclass, field

SHELL = "index.html"
NEVER_KEPT = "no-store"
KEPT_FOR_GOOD = "max-age=31536000, immutable"      # a year: the customary lifetime of a versioned file
ASK_EACH_TIME = "no-cache"
# a file changed this recently gets no Last-Modified: a second change within the same second would keep its date
# (HTTP dates count whole seconds), and a browser holding the first one would be told it is unchanged
SETTLED_S = 2.0

# src="name" / href="name" attributes of the page shell naming a plain relative file (no scheme, query, fragment,
# "./" or data: URL), not part of a longer attribute name (data-src) or of a script's text (img.src)
_REFERENCE = re.compile(rb'(?<![\w.\-])(src|href)="([A-Za-z0-9_][A-Za-z0-9_.\-/]*)"')


def version_of(data: bytes) -> str:
    """The version of a file with the bytes ``data``: its BLAKE2b digest of 8 bytes (``b2sum -l 64``) in hexadecimal."""
    return hashlib.blake2b(data, digest_size=8).hexdigest()


@dataclass(frozen=True)
class Answer:
    """What to send for one static file: ``status`` 200 with ``body``, or 304 with no body; ``cache`` the
    Cache-Control value; ``validators`` the ETag and Last-Modified headers (none for the page shell)."""

    status: int
    body: bytes
    cache: str
    validators: dict[str, str] = field(default_factory=dict)


class Assets:
    """The static files under ``root`` (a resolved folder): their versions and the answers that let the browser
    keep them."""

    def __init__(self, root: pathlib.Path) -> None:
        self.root = root
        self.shell_path = root / SHELL

    def find(self, relative: str) -> pathlib.Path | None:
        """The file ``relative`` names inside the root, or None (outside it, missing, not a file, or a name the
        system refuses, such as one too long)."""
        try:
            target = (self.root / relative).resolve()
            if self.root not in target.parents or not target.is_file():
                return None
        except (OSError, ValueError):          # ENAMETOOLONG, ELOOP ...; ValueError: a NUL in the name
            return None
        return target

    def answer(self, target: pathlib.Path, asked_version: str | None, if_none_match: str | None,
               if_modified_since: str | None) -> Answer:
        """The answer for the file ``target`` (found by ``find``), asked for with the query's ``v`` and the
        request's ``If-None-Match`` and ``If-Modified-Since`` headers. OSError: the file cannot be read."""
        before = target.stat().st_mtime_ns
        data = target.read_bytes()
        if target == self.shell_path:
            return Answer(200, self.shell(data), NEVER_KEPT)
        version = version_of(data)
        validators = {"ETag": f'"{version}"'}
        modified = before / 1e9
        if target.stat().st_mtime_ns == before and time.time() - modified >= SETTLED_S:
            validators["Last-Modified"] = email.utils.formatdate(modified, usegmt=True)
        cache = KEPT_FOR_GOOD if asked_version == version else ASK_EACH_TIME
        if if_none_match is not None:          # it decides alone when present (RFC 9110 13.2.2)
            unchanged = _matches(if_none_match, validators["ETag"])
        else:
            unchanged = "Last-Modified" in validators and _not_since(if_modified_since, modified)
        return Answer(304 if unchanged else 200, b"" if unchanged else data, cache, validators)

    def shell(self, data: bytes) -> bytes:
        """The page shell with each file of the root it names given its version (one that cannot be read keeps its
        plain name: asking for it then gives the reason)."""
        def versioned(match: re.Match[bytes]) -> bytes:
            target = self.find(match.group(2).decode("ascii"))
            if target is None or target == self.shell_path:
                return match.group(0)
            try:
                version = version_of(target.read_bytes())
            except OSError:
                return match.group(0)
            return match.group(1) + b'="' + match.group(2) + b"?v=" + version.encode() + b'"'
        return _REFERENCE.sub(versioned, data)


def asked_version(query: str) -> str | None:
    """The ``v`` of an address's query (the first one), None without one."""
    return next((part[2:] for part in query.split("&") if part.startswith("v=")), None)


def _matches(if_none_match: str, etag: str) -> bool:
    """Whether an If-None-Match value (``*`` or a list of entity tags, weak ones included) names ``etag``."""
    tags = [t.strip() for t in if_none_match.split(",")]
    return "*" in tags or any(t.removeprefix("W/") == etag for t in tags)


def _not_since(if_modified_since: str | None, modified: float) -> bool:
    """Whether the file, last modified at ``modified`` (epoch seconds), is unchanged since an If-Modified-Since
    date (False when there is none or it is not an HTTP date)."""
    if not if_modified_since:
        return False
    try:
        since = email.utils.parsedate_to_datetime(if_modified_since).timestamp()
    except (TypeError, ValueError, IndexError, OverflowError):
        return False
    return int(modified) <= since

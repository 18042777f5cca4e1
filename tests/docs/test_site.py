"""The documentation site: built with `mkdocs build --strict` (as .ci/run builds it) and opened
in headless chromium over HTTP from this machine (127.0.0.1), driven through the DevTools
protocol on a pipe: the front page loads without a script error, a query typed into the
search box finds the page that holds it (Material's search runs in the browser, in a web worker
over search_index.json), and a page of the API reference shows a function's docstring.

Without chromium the browser checks skip, saying how to get one; the build itself always runs."""
import functools
import html
import http.server
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")


def build_site(dest):
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(dest)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-4000:]
    return dest


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    return build_site(tmp_path_factory.mktemp("site") / "site")


def test_the_site_builds_strict_with_every_page_and_this_machines_benchmarks(site):
    for page in ("getting-started", "tour", "walkers", "shapes", "mjcf-gymnasium", "gait-analysis",
                 "controllers", "cli", "engine", "debugging", "benchmarks", "api/builder"):
        assert (site / page / "index.html").is_file(), page
    # the search index holds every page (Material's search reads it in the browser)
    index = json.loads((site / "search" / "search_index.json").read_text())
    assert {d["location"].split("#")[0] for d in index["docs"]} >= {"", "engine/", "api/builder/"}
    # the benchmarks page shows each committed results file, as `planarsim bench --md` wrote it
    results = sorted((ROOT / "benchmarks" / "results").glob("*.md"))
    assert results
    page = (site / "benchmarks" / "index.html").read_text()
    for path in results:
        heading = path.read_text().splitlines()[0].removeprefix("## Measured on ").strip("`")
        assert heading in page, path.name
    # the engine page's table of the stages is the one planarsim/kernels/stages.py writes
    from planarsim.kernels.stages import STAGES
    engine = html.unescape(re.sub(r"<[^>]+>", "", (site / "engine" / "index.html").read_text()))
    assert "stage-table" not in engine
    for k, (name, what, modules, functions) in enumerate(STAGES):
        assert f"{k + 1}. {name}" in engine and " ".join(what.split()) in " ".join(engine.split()), name
        assert all(f in engine for f in functions), (name, functions)
    # the two commands come from README.md itself (its section between the snippet markers)
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("--8<-- [start:two-commands]"):readme.index("--8<-- [end:two-commands]")]
    commands = re.findall(r"^python3 -m venv .*$", section, re.M)
    page = html.unescape(re.sub(r"<[^>]+>", "", (site / "getting-started" / "index.html").read_text()))
    assert len(commands) == 2 and all(c in page for c in commands)


class Chromium:
    """Headless chromium (the launch flags of tests/render/test_html.py, a fresh profile)
    driven over --remote-debugging-pipe: DevTools protocol messages, each ending in a NUL byte,
    written to its fd 3 and read from its fd 4."""

    def __init__(self, exe):
        to_browser, self._to_browser = os.pipe()
        self._from_browser, from_browser = os.pipe()
        self.profile = tempfile.mkdtemp(prefix="chromium-profile-")

        def fds():  # in the child, before exec: the pipes on fds 3 and 4
            a, b = os.dup(to_browser), os.dup(from_browser)
            os.dup2(a, 3)
            os.dup2(b, 4)

        os.set_inheritable(self._to_browser, False)
        os.set_inheritable(self._from_browser, False)
        self.proc = subprocess.Popen(
            [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--no-first-run", f"--user-data-dir={self.profile}", "--remote-debugging-pipe", "about:blank"],
            close_fds=False, preexec_fn=fds, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_browser)
        os.close(from_browser)
        self._buf, self._id, self.events = b"", 0, []
        target = self.send("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        self.send("Runtime.enable", session=self.session)
        self.send("Page.enable", session=self.session)

    def send(self, method, session=None, **params):
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        os.write(self._to_browser, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._read()
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def _read(self):
        deadline = time.monotonic() + 60
        while b"\0" not in self._buf:
            if time.monotonic() > deadline:
                raise TimeoutError("chromium did not answer within 60 s")
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                raise RuntimeError("chromium closed its pipe")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def js(self, expression):
        res = self.send("Runtime.evaluate", session=self.session, expression=expression, returnByValue=True)
        if "exceptionDetails" in res:
            raise RuntimeError(f"{expression}: {res['exceptionDetails']}")
        return res["result"].get("value")

    def wait_for(self, expression, seconds=30.0):
        """The expression's value once it is truthy (polled every 0.1 s), else None."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            value = self.js(expression)
            if value:
                return value
            time.sleep(0.1)
        return None

    def open(self, url):
        self.events.clear()
        self.send("Page.navigate", session=self.session, url=url)
        assert self.wait_for(f"document.readyState === 'complete' && location.href === {json.dumps(url)}"), url

    def script_errors(self):
        self.js("0")  # collect the events that came before
        return [e["params"]["exceptionDetails"].get("text", "") + " "
                + str(e["params"]["exceptionDetails"].get("exception", {}).get("description", ""))
                for e in self.events if e.get("method") == "Runtime.exceptionThrown"]

    def close(self):
        self.proc.kill()
        self.proc.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)
        shutil.rmtree(self.profile, ignore_errors=True)


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def browser(site):
    exe = next((shutil.which(n) for n in CHROMIUM_NAMES if shutil.which(n)), None)
    if exe is None:
        pytest.skip("no chromium on PATH: the site was built but not opened in a browser "
                    "(install one: `apt-get install -y chromium` on Debian; .ci/run does this)")
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                             functools.partial(_QuietHandler, directory=str(site)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    chrome = Chromium(exe)
    try:
        yield chrome, f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        chrome.close()
        server.shutdown()
        server.server_close()


def test_front_page_opens_without_a_script_error(browser):
    chrome, base = browser
    chrome.open(base)
    assert chrome.js("document.title") == "planarsim"
    text = " ".join(chrome.js("document.body.innerText").split())
    assert "An exact, fast planar (2D) physics engine for walking machines" in text
    # the navigation names the pages, and the pictures load
    for name in ("Getting started", "How the engine works", "Benchmarks", "API reference"):
        assert name in text, name
    assert chrome.wait_for("[...document.images].filter(i => i.src.endsWith('.gif'))"
                           ".every(i => i.complete && i.naturalWidth > 0) && document.images.length >= 6")
    assert chrome.script_errors() == []


def test_search_finds_the_page_that_holds_a_query(browser):
    """A query typed into the search box key by key (the DevTools protocol's key events, as a
    keyboard sends them) lists the engine page's section that holds it; a word no page holds
    lists none."""
    chrome, base = browser

    chrome.open(base)
    chrome.js("document.querySelector('label[for=__search]').click()")
    box = "document.querySelector('input[data-md-component=search-query]')"
    meta = "document.querySelector('.md-search-result__meta').textContent"
    links = "[...document.querySelectorAll('.md-search-result__item a')].map(a => a.href)"

    def type_query(text):   # key by key, replacing what the box holds
        chrome.js(f"{box}.focus(); {box}.select()")
        for ch in text:
            chrome.send("Input.dispatchKeyEvent", session=chrome.session, type="keyDown", key=ch, text=ch,
                        unmodifiedText=ch)
            chrome.send("Input.dispatchKeyEvent", session=chrome.session, type="keyUp", key=ch)
        assert chrome.js(f"{box}.value") == text

    type_query("Newton-SHAKE")
    found = chrome.wait_for(f"{links}.length && {links}")       # the worker has indexed the site
    assert found, chrome.js(meta)
    assert re.match(r"\d+ matching documents?", chrome.js(meta)), chrome.js(meta)
    assert any(re.search(r"/engine/\?h=[^#]*#8-positions$", link) for link in found), found
    # a word no page holds: the list empties and says so
    type_query("xylophonequux")
    assert chrome.wait_for(f"{links}.length === 0 && /^No matching/.test({meta})"), (chrome.js(meta), chrome.js(links))
    assert chrome.script_errors() == []


def test_api_reference_shows_a_functions_docstring(browser):
    from planarsim.builder import ModelBuilder
    chrome, base = browser
    chrome.open(base + "api/builder/")
    anchor = "planarsim.builder.ModelBuilder.add_box_contacts"
    text = chrome.wait_for(f"document.getElementById({json.dumps(anchor)}) && "
                           f"document.getElementById({json.dumps(anchor)}).parentElement.innerText")
    assert text, anchor
    first = inspect.getdoc(ModelBuilder.add_box_contacts).split(".")[0]   # its first sentence
    assert " ".join(first.split()) in " ".join(text.split())
    assert "add_box_contacts" in text

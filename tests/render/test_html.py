"""The HTML player (planarsim/render/html.py): a self-contained page that plays by itself, in node
and in a real browser."""

import re
import shutil
import subprocess

import pytest

from planarsim.render import export_animation, show_inline


def test_html_export_is_a_self_contained_player(sliding_run, tmp_path):
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=15, size=(1.6, 0.9), dpi=50, progress=False)
    page = out.read_text()
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert page.count("data:image/png;base64,") == 30          # frames embedded
    assert "play_animation()" in page and 'type="range"' in page  # play button and frame slider
    assert "http://" not in page and "https://" not in page      # nothing fetched from the net
    frag = show_inline(traj, model, fps=5, size=(1.6, 0.9), dpi=50)
    html = frag.data if hasattr(frag, "data") else frag
    try:
        import IPython  # noqa: F401
        assert type(frag).__name__ == "HTML"
    except ImportError:
        assert isinstance(frag, str)  # without IPython, the HTML string itself
    assert html.count("data:image/png;base64,") == 10
    assert "<html>" not in html


def test_html_export_over_its_size_cap_is_an_error_not_a_short_page(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match="embed limit"):
        export_animation(traj, model, tmp_path / "big.html", fps=10, size=(1.6, 0.9), dpi=50,
                         progress=False, embed_limit_mb=0.01)
    assert list(tmp_path.iterdir()) == []


NODE_DOM_STUB = r"""
const fs = require('fs'); const vm = require('vm');
const html = fs.readFileSync(process.argv[2], 'utf8');
const els = {};
function el(id) { if (!els[id]) els[id] = {id, value: 0, max: 0, src: '', getAttribute: () => null,
                                          setAttribute: () => {}}; return els[id]; }
const sandbox = {navigator: {userAgent: 'node'}, Image: function() { this.src = ''; },
  setTimeout, setInterval, clearInterval, console,
  document: {getElementById: el}};
const form = html.match(/name="(_anim_loop_select\w+)"/)[1];
sandbox.document[form] = {state: [{value: 'once', checked: false}, {value: 'loop', checked: true},
                                   {value: 'reflect', checked: false}]};
vm.createContext(sandbox);
const scripts = [...html.matchAll(/<script[^>]*>([\s\S]*?)<\/script>/g)].map(m => m[1]);
for (const s of scripts) vm.runInContext(s, sandbox);
setTimeout(() => {
  const slider = html.match(/id="(_anim_slider\w+)"/)[1];
  const button = (title) => html.match(new RegExp(`title="${title}" aria-label="${title}" onclick="([^"]+)"`))[1];
  const autoplayed = el(slider).value;                 // nobody pressed Play: the page plays by itself
  vm.runInContext(button('Pause'), sandbox);
  const paused = el(slider).value;
  setTimeout(() => {
    const still = el(slider).value;
    vm.runInContext(button('Play'), sandbox);
    setTimeout(() => { console.log(JSON.stringify({autoplayed, paused, still, after: el(slider).value,
                                                   max: el(slider).max}));
                       process.exit(0); }, 300);
  }, 200);
}, 400);
"""


def test_html_player_script_runs_plays_by_itself_and_pauses(sliding_run, tmp_path):
    """The page's own JavaScript run in node (V8) against a minimal DOM: no script error, the
    page starts playing on its own, Pause holds the frame and Play moves it on. (Not a browser:
    see the chromium test.)"""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed: cannot run the player's JavaScript")
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=30, size=(1.6, 0.9), dpi=50, progress=False)
    (tmp_path / "stub.js").write_text(NODE_DOM_STUB)
    res = subprocess.run([node, str(tmp_path / "stub.js"), str(out)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    import json
    state = json.loads(res.stdout.strip().splitlines()[-1])
    assert state["max"] == 59
    assert 3 <= state["autoplayed"] <= 59      # 33 ms per frame for 400 ms: about 12 frames
    assert state["still"] == state["paused"]
    assert state["after"] != state["paused"]


CHROMIUM_PROBE = """<script>
window.__errors = [];
window.addEventListener('error', function (e) { window.__errors.push(String(e.message)); });
</script>"""


CHROMIUM_DRIVER = """<script>
setTimeout(function () {
  var slider = document.querySelector('input.anim-slider');
  var before = slider.value;
  document.querySelector('button[title="Pause"]').click();
  setTimeout(function () {
    var out = document.createElement('pre'); out.id = 'result';
    out.textContent = 'RESULT ' + before + ' ' + slider.value + ' ERRORS ' + window.__errors.length + ' '
                      + window.__errors.join('|');
    document.body.appendChild(out);
  }, 1000);
}, 300);
</script>"""


CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")


def _find_chromium():
    return next((shutil.which(n) for n in CHROMIUM_NAMES if shutil.which(n)), None)


def chromium_or_skip():
    """A headless browser on PATH (Debian's chromium, which .ci/run installs before the suite),
    else the test is skipped saying how to get one."""
    exe = _find_chromium()
    if exe is None:
        pytest.skip("no chromium on PATH: the in-browser check of the HTML export did not run "
                    "(install one: `apt-get install -y chromium` on Debian; .ci/run does this)")
    return exe


def test_html_export_plays_in_headless_chromium(sliding_run, tmp_path):
    """The exported page in a real browser (Debian's chromium, headless): it loads without a
    script error, plays by itself (the frame slider has moved before anyone presses a button)
    and Pause holds the frame."""
    exe = chromium_or_skip()
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=30, size=(1.6, 0.9), dpi=50, progress=False)
    page = out.read_text().replace("<head>", "<head>" + CHROMIUM_PROBE, 1).replace("</body>", CHROMIUM_DRIVER + "</body>")
    out.write_text(page)
    res = subprocess.run([exe, "--headless", "--disable-gpu", "--no-sandbox", "--virtual-time-budget=5000",
                          "--dump-dom", out.as_uri()], capture_output=True, text=True, timeout=120)
    # the page's DOM after 5 s of virtual time; the driver's script text is in it too
    found = re.search(r'<pre id="result">RESULT (\S+) (\S+) ERRORS (\d+) ?([^<]*)</pre>', res.stdout)
    assert found is not None, (res.stdout[-1000:], res.stderr[-2000:])
    before, after, n_err = int(found[1]), int(found[2]), int(found[3])
    assert n_err == 0, found[4]
    assert before > 0 and after == before

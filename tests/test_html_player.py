"""The HTML episode player (`ronap run --html`, `ronap replay --html`, the players `ronap compare`
links) opened in a real headless browser: Debian's chromium driven by Playwright (never
Playwright's own browser download). The canvas must draw each robot at its logged pose, at the
first step and at a step the scrubber or the keyboard reaches; the side panel must show the logged
action; and the page must ask the network for nothing."""

import csv
import pathlib
import subprocess

import pytest

sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")

CHROMIUM = pathlib.Path("/usr/bin/chromium")

# The lone robot's colour (render::PATH) and a team's first robots' (render::chart::policy_colour).
LONE = (40, 80, 230)
TEAM = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40)]


@pytest.fixture(scope="module")
def browser():
    if not CHROMIUM.exists():
        pytest.skip("no /usr/bin/chromium (apt-get install chromium; .ci/run installs it)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM))
        yield b
        b.close()


class Page:
    """A player page opened in `browser`, every request it makes recorded (and only the page's
    own file let through)."""

    def __init__(self, browser, path: pathlib.Path, width: int = 1280):
        self.url = path.resolve().as_uri()
        self.page = browser.new_page(viewport={"width": width, "height": 900})
        self.requests: list[str] = []
        self.errors: list[str] = []

        def route(r):
            self.requests.append(r.request.url)
            if r.request.url == self.url:
                r.continue_()
            else:
                r.abort()

        self.page.route("**/*", route)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.goto(self.url)
        self.page.wait_for_function("window.ronap && (window.ronap.ready || window.ronap.error)", timeout=60_000)
        assert self.page.evaluate("window.ronap.error") is None
        assert self.errors == []

    def pixel(self, player: int, x: float, y: float) -> tuple[int, int, int]:
        """The colour the canvas of `player` has at scene point (x, y), the view placed as the
        page places the whole scene: fitted to the canvas, centred, y up."""
        return tuple(
            self.page.evaluate(
                """([i, x, y]) => {
                    const p = window.ronap.players[i];
                    const c = p.canvas;
                    const [W, H] = p.meta.scene;
                    const s = Math.min(c.width / W, c.height / H);
                    const px = (c.width - W * s) / 2 + x * s;
                    const py = (c.height + H * s) / 2 - y * s;
                    return Array.from(c.getContext("2d").getImageData(Math.floor(px), Math.floor(py), 1, 1).data.slice(0, 3));
                }""",
                [player, x, y],
            )
        )

    def action(self, player: int = 0) -> str:
        return self.page.locator("section.player").nth(player).locator(".panel .action").inner_text()

    def scrub(self, step: int) -> None:
        self.page.eval_on_selector(
            "#scrub", "(e, v) => { e.value = String(v); e.dispatchEvent(new Event('input')); }", step
        )

    def frame(self) -> str:
        return self.page.locator("#frame").inner_text()

    def close(self) -> None:
        assert self.requests == [self.url], f"the page asked for more than itself: {self.requests}"
        self.page.close()


def steps_of(path: pathlib.Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def same_action(shown: str, logged: str) -> bool:
    """Whether the panel's action is the logged one: a discrete action by name, a continuous one
    (`v=..;w=..`) to the panel's four decimals."""
    if not logged.startswith("v="):
        return shown == logged
    numbers = [[float(p.split("=")[1]) for p in a.split(";")] for a in (shown, logged)]
    return all(abs(a - b) <= 1e-4 * max(1.0, abs(b)) for a, b in zip(*numbers))


def near(colour, expected, tolerance=8) -> bool:
    return all(abs(a - b) <= tolerance for a, b in zip(colour, expected))


def run(ronap_bin, *args, cwd):
    return subprocess.run([ronap_bin, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_a_run_player_draws_the_logged_poses_and_shows_the_logged_actions(ronap_bin, browser, tmp_path):
    done = run(ronap_bin, "run", "--policy", "apf", "--seeds", "4", "--html", "failures", "--log-steps",
               "--out", "r", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(open(tmp_path / "r" / "episodes.csv")))
    failed = [r for r in rows if r["outcome"] != "success"]
    pages = sorted((tmp_path / "r" / "html").iterdir())
    # One page per failed episode, named by seed and outcome; none for the successes.
    assert [p.name for p in pages] == [f"seed-{int(r['seed']):06d}-{r['outcome']}.html" for r in failed]
    assert failed, "apf failed no episode of seeds 0..3: the test checks nothing"
    seed = int(failed[0]["seed"])
    log = steps_of(tmp_path / "r" / "steps" / f"seed-{seed:06d}.csv")
    page = Page(browser, pages[0])
    first = log[0]
    assert near(page.pixel(0, float(first["x"]), float(first["y"])), LONE)
    assert page.action() == first["action"]
    assert page.frame() == f"step 0 of {len(log)}"
    # A step the scrubber reaches: the robot is at that step's logged pose, and no longer where
    # it started.
    k = len(log) // 2
    page.scrub(k)
    row = log[k]
    assert page.frame() == f"step {k} of {len(log)}"
    assert near(page.pixel(0, float(row["x"]), float(row["y"])), LONE)
    moved = abs(float(row["x"]) - float(first["x"])) + abs(float(row["y"]) - float(first["y"]))
    assert moved > 20, "the robot hardly moved: the next check cannot fail"
    assert not near(page.pixel(0, float(first["x"]), float(first["y"])), LONE)
    assert page.action() == row["action"]
    # The keyboard: the right arrow steps on, the left arrow back.
    page.page.keyboard.press("ArrowRight")
    assert page.frame() == f"step {k + 1} of {len(log)}"
    assert page.action() == log[k + 1]["action"]
    assert near(page.pixel(0, float(log[k + 1]["x"]), float(log[k + 1]["y"])), LONE)
    page.page.keyboard.press("ArrowLeft")
    page.page.keyboard.press("ArrowLeft")
    assert page.frame() == f"step {k - 1} of {len(log)}"
    # The last step shows the outcome and no action.
    page.page.keyboard.press("End")
    assert "ended" in page.action()
    headline = page.page.locator("section.player .headline").inner_text()
    assert failed[0]["outcome"] in headline
    # Space plays: the step moves on by itself.
    page.page.keyboard.press("Home")
    page.page.keyboard.press(" ")
    page.page.wait_for_function("window.ronap.state.frame > 3", timeout=10_000)
    page.page.keyboard.press(" ")
    assert page.page.evaluate("window.ronap.state.playing") is False
    page.close()


def test_a_team_player_draws_every_robot_in_its_colour(ronap_bin, root, browser, tmp_path):
    scenario = root / "scenarios" / "warehouse-team.toml"
    done = run(ronap_bin, "run", "--scenario", str(scenario), "--policy", "coordinated", "--seeds", "1",
               "--html", "1", "--log-steps", "--out", "t", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    (path,) = (tmp_path / "t" / "html").iterdir()
    logs = [steps_of(tmp_path / "t" / "steps" / f"seed-000000-robot-{k}.csv") for k in range(4)]
    page = Page(browser, path)
    for k, log in enumerate(logs):
        assert near(page.pixel(0, float(log[0]["x"]), float(log[0]["y"])), TEAM[k]), f"robot {k}"
    step = 40
    page.scrub(step)
    for k, log in enumerate(logs):
        row = log[step]
        assert int(row["step"]) == step + 1
        assert near(page.pixel(0, float(row["x"]), float(row["y"])), TEAM[k]), f"robot {k}"
    # The panel shows the chosen robot's step.
    page.page.select_option("#robot", "2")
    assert same_action(page.action(), logs[2][step]["action"])
    page.page.evaluate("document.activeElement.blur()")
    # `f` follows the next robot: the view zooms in round it, so it sits in the canvas' middle.
    page.page.keyboard.press("f")
    page.page.keyboard.press("f")
    assert page.page.evaluate("[window.ronap.state.follow, window.ronap.state.robot]") == [True, 3]
    centre = page.page.evaluate(
        "(() => { const c = window.ronap.players[0].canvas; const d = c.getContext('2d')"
        ".getImageData(Math.floor(c.width / 2), Math.floor(c.height / 2), 1, 1).data; return [d[0], d[1], d[2]]; })()"
    )
    assert near(centre, TEAM[3])
    page.close()


def test_replay_writes_a_player_from_a_step_log_and_refuses_bad_paths(ronap_bin, browser, tmp_path):
    done = run(ronap_bin, "run", "--policy", "geodesic", "--seeds", "2", "--log-steps", "--out", "r", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    log_path = tmp_path / "r" / "steps" / "seed-000001.csv"
    done = run(ronap_bin, "replay", str(log_path), "--html", "p.html", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "p.html: seed 1" in done.stdout
    log = steps_of(log_path)
    page = Page(browser, tmp_path / "p.html")
    assert near(page.pixel(0, float(log[0]["x"]), float(log[0]["y"])), LONE)
    assert page.action() == log[0]["action"]
    page.scrub(len(log) - 1)
    assert near(page.pixel(0, float(log[-1]["x"]), float(log[-1]["y"])), LONE)
    assert page.action() == log[-1]["action"]
    page.close()
    # A name that is not .html, and a directory that does not exist: an error naming the value,
    # no file left behind.
    bad = run(ronap_bin, "replay", str(log_path), "--html", "p.txt", cwd=tmp_path)
    assert bad.returncode != 0 and "--html p.txt" in bad.stderr and "panicked" not in bad.stderr
    assert not (tmp_path / "p.txt").exists()
    bad = run(ronap_bin, "replay", str(log_path), "--html", "no/such/dir/p.html", cwd=tmp_path)
    assert bad.returncode != 0 and "no/such/dir/p.html" in bad.stderr and "panicked" not in bad.stderr
    assert not (tmp_path / "no").exists()
    bad = run(ronap_bin, "run", "--policy", "apf", "--seeds", "2", "--html", "some", "--out", "x", cwd=tmp_path)
    assert bad.returncode == 2 and "some" in bad.stderr and "--html" in bad.stderr
    assert not (tmp_path / "x").exists()


def test_compare_links_each_disagreement_to_a_shared_timeline(ronap_bin, browser, tmp_path):
    done = run(ronap_bin, "compare", "--policy", "apf", "--policy", "geodesic", "--seeds", "6",
               "--out", "c", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "c" / "report.html").read_text()
    rows = list(csv.DictReader(open(tmp_path / "c" / "seeds.csv")))
    split = [
        int(r["seed"])
        for r in rows
        if (r["apf_outcome"] == "success") != (r["geodesic_outcome"] == "success")
    ]
    assert split, "apf and geodesic agree on every seed: the test checks nothing"
    for s in split:
        assert f'href="players/seed-{s:06d}.html"' in report
    page = Page(browser, tmp_path / "c" / "players" / f"seed-{split[0]:06d}.html")
    assert page.page.locator("section.player").count() == 2
    frames = page.page.evaluate("window.ronap.players.map(p => p.meta.frames)")
    page.scrub(max(frames) - 1)
    # One timeline: both panels at the step the scrubber chose (the shorter episode at its end).
    for i, f in enumerate(frames):
        assert page.page.locator("section.player").nth(i).locator(".panel td").first.inner_text() == (
            f"{min(max(frames) - 1, f - 1)} of {f - 1}"
        )
    page.close()


def test_the_page_fits_a_phone(ronap_bin, browser, tmp_path):
    done = run(ronap_bin, "run", "--policy", "apf", "--seeds", "1", "--html", "all", "--out", "r", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    (path,) = (tmp_path / "r" / "html").iterdir()
    page = Page(browser, path, width=390)
    assert page.page.evaluate("document.documentElement.scrollWidth") <= 390
    box = page.page.locator("canvas").bounding_box()
    assert box is not None and box["width"] <= 390 and box["width"] > 300
    page.close()

"""How long an HTML player page (`ronap run --html`, `ronap replay --html`) takes to load: from
navigation until the page has inflated its numbers, decoded its scene picture and drawn the first
step (`window.ronap.ready`), and one redraw at the last step, in Debian's chromium driven by
Playwright (pip install playwright; apt-get install chromium). Usage:

    python scripts/player-load.py PAGE.html [PAGE.html ...] [--runs N]
"""

import argparse
import pathlib
import time

from playwright.sync_api import sync_playwright


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pages", nargs="+", type=pathlib.Path)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    args = parser.parse_args()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=args.chromium)
        for path in args.pages:
            loads, redraws = [], []
            for _ in range(args.runs):
                page = browser.new_page(viewport={"width": 1280, "height": 900})
                start = time.perf_counter()
                page.goto(path.resolve().as_uri())
                page.wait_for_function("window.ronap && (window.ronap.ready || window.ronap.error)", polling=5, timeout=120_000)
                loads.append(time.perf_counter() - start)
                error = page.evaluate("window.ronap.error")
                if error:
                    raise SystemExit(f"{path}: {error}")
                redraws.append(page.evaluate("() => { const t = performance.now(); window.ronap.go(1e9); return performance.now() - t; }"))
                page.close()
            size = path.stat().st_size
            print(
                f"{path}: {size / 1e6:.2f} MB, load {1000 * min(loads):.0f}-{1000 * max(loads):.0f} ms, "
                f"redraw at the last step {min(redraws):.0f}-{max(redraws):.0f} ms ({args.runs} runs)"
            )
        browser.close()


if __name__ == "__main__":
    main()

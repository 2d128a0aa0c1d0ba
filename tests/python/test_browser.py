"""The scene builder page in a real browser: Debian's headless Chromium driven by
Playwright (the PyPI package, with the system browser; nothing is downloaded). It loads
the page served by `smoothtrace serve`, drags to orbit and sees a new image, changes
alpha and sees another, probes a pixel, saves the view as TOML (downloaded and on the
server) and checks that `smoothtrace render` renders that TOML to the image the page's
"Render full PNG" downloads. With SMOOTHTRACE_SCREENSHOT=1 it writes the README's
screenshot, renders/serve.png.

Skips, saying why, when Chromium or Playwright is missing."""

import json
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

from conftest import ROOT
from pngread import read_png

CHROMIUM = os.environ.get("SMOOTHTRACE_CHROMIUM", "/usr/bin/chromium")
# The flags a sandboxed, offline machine needs (no background connections, no GPU).
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@pytest.fixture(scope="module")
def playwright_sync():
    if not pathlib.Path(CHROMIUM).is_file():
        pytest.skip(f"no Chromium at {CHROMIUM} (apt-get install chromium, or set SMOOTHTRACE_CHROMIUM)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("the playwright package is not installed (pip install playwright)")
    with sync_playwright() as p:
        yield p


@pytest.fixture()
def served(cli, tmp_path):
    """`smoothtrace serve` on the built-in torus scene, copied to a temporary folder,
    with server-side saving on; yields (url, folder)."""
    shutil.copy(ROOT / "scenes" / "torus.toml", tmp_path / "torus.toml")
    proc = subprocess.Popen(
        [str(cli), "serve", "torus.toml", "--port", "0", "--save", "saved.toml"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = proc.stdout.readline()
    url = next((w for w in line.split() if w.startswith("http://")), None)
    if url is None:
        proc.kill()
        pytest.fail(f"serve printed no URL: {line!r} {proc.stderr.read()}")
    yield url, tmp_path
    proc.send_signal(2)
    try:
        assert proc.wait(timeout=30) == 0, proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()


def image_of(page, tmp_path, name):
    """The page's current image element as pixels (a screenshot of the element)."""
    path = tmp_path / name
    page.locator("#view").screenshot(path=str(path))
    return read_png(path)[..., :3]


def wait_for_pass(page, after):
    """Waits until a full-resolution pass finished after `after` completed loops."""
    page.wait_for_function(
        f"Number(document.getElementById('view').dataset.completed || 0) > {after}",
        timeout=60_000,
    )
    return int(page.locator("#view").get_attribute("data-completed"))


def test_orbit_alpha_probe_save_in_chromium(playwright_sync, served, cli, tmp_path):
    url, folder = served
    browser = playwright_sync.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
    try:
        page = browser.new_page(viewport={"width": 1360, "height": 760}, accept_downloads=True)
        errors = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        done = wait_for_pass(page, 0)
        first = image_of(page, tmp_path, "first.png")
        assert first.shape[:2] == (540, 960)
        assert (first != 255).any(), "the first image is empty"

        # Drag to orbit: a new view, refined to full resolution.
        box = page.locator("#view").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(cx, cy)
        page.mouse.down()
        for i in range(1, 11):
            page.mouse.move(cx + 12 * i, cy + 3 * i)
        page.mouse.up()
        done = wait_for_pass(page, done)
        page.wait_for_timeout(300)
        orbited = image_of(page, tmp_path, "orbited.png")
        assert np.abs(orbited - first).sum() > 0, "dragging did not change the image"

        # Change alpha (the log slider): a softer surface, another image.
        page.evaluate(
            """() => { const s = document.getElementById('obj0-alpha');
                       s.value = String(Number(s.value) - 0.6);
                       s.dispatchEvent(new Event('input')); }"""
        )
        done = wait_for_pass(page, done)
        page.wait_for_timeout(300)
        softer = image_of(page, tmp_path, "softer.png")
        assert np.abs(softer - orbited).sum() > 0, "changing alpha did not change the image"
        alpha_text = page.locator("#obj0-alpha + br + span").inner_text()
        assert "x diagonal" in alpha_text

        # Probe the pixel at the centre of the torus' near side.
        page.mouse.click(box["x"] + 480, box["y"] + 400)
        page.wait_for_function("document.getElementById('probe').dataset.json !== undefined")
        probe = json.loads(page.locator("#probe").get_attribute("data-json"))
        assert probe["hit"], probe
        assert abs(probe["s"]) < 2e-3 and probe["distance"] > 0, probe
        assert probe["nearest_kind"] == "triangles"
        assert "exact distance" in page.locator("#probe").inner_text()

        # Save: the download and the server's copy are the same TOML.
        with page.expect_download() as dl:
            page.click("#save")
        downloaded = folder / "downloaded.toml"
        dl.value.save_as(downloaded)
        page.click("#save-server")
        page.wait_for_function("document.getElementById('status').textContent.startsWith('saved to')")
        saved = folder / "saved.toml"
        assert saved.read_text() == downloaded.read_text()

        # The page's full PNG equals `smoothtrace render` of the saved TOML.
        with page.expect_download(timeout=60_000) as dl:
            page.click("#png")
        page_png = folder / "page.png"
        dl.value.save_as(page_png)
        r = subprocess.run(
            [str(cli), "render", "saved.toml", "-o", "cli.png"], cwd=folder, capture_output=True, text=True
        )
        assert r.returncode == 0, r.stderr
        a, b = read_png(page_png), read_png(folder / "cli.png")
        assert a.shape == b.shape and (a == b).all(), "the saved TOML renders a different image"

        if os.environ.get("SMOOTHTRACE_SCREENSHOT"):
            page.screenshot(path=str(ROOT / "renders" / "serve.png"))
        assert not errors, errors
    finally:
        browser.close()

"""A served scene as a PNG, without a person: headless Chromium (Debian's ``chromium`` and
``chromium-driver``, driven by selenium) opens the viser page and a screenshot is written. WebGL
runs on the CPU (SwiftShader), so no GPU or display is needed. Nothing is downloaded: the browser
and its driver are the Debian packages' binaries, given to selenium by path."""
from __future__ import annotations

import os
import shutil
import time
from pathlib import Path
from typing import Dict, List, Optional

import numpy as np

from .. import progress

BROWSERS = ("chromium", "chromium-browser")
DRIVERS = ("chromedriver",)
PACKAGES = "chromium chromium-driver"


class NoBrowser(RuntimeError):
    """Headless Chromium or its driver is not installed."""


def find_browser() -> tuple:
    """(browser, driver) paths, or NoBrowser naming the Debian packages to install."""
    browser = next((p for p in map(shutil.which, BROWSERS) if p), None)
    driver = next((p for p in map(shutil.which, DRIVERS) if p), None)
    if browser is None or driver is None:
        raise NoBrowser(f"headless Chromium is not installed (Debian packages: {PACKAGES})")
    return browser, driver


def _variance(png: bytes) -> float:
    from io import BytesIO

    import matplotlib.image as mpimg

    return float(np.asarray(mpimg.imread(BytesIO(png), format="png"))[..., :3].var())


def _driver(size):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    browser, driver = find_browser()
    os.environ.setdefault("SE_OFFLINE", "true")         # selenium manager: never fetch a browser or driver
    opts = webdriver.ChromeOptions()
    opts.binary_location = browser
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", f"--window-size={size[0]},{size[1]}"):
        opts.add_argument(a)
    return webdriver.Chrome(service=Service(executable_path=driver), options=opts)


def _drawn(d, timeout: float, min_variance: float, settle: float) -> bytes:
    """A screenshot once the page has drawn something (pixel variance above ``min_variance``) and
    a further ``settle`` seconds have passed."""
    deadline, png = time.monotonic() + timeout, b""
    while time.monotonic() < deadline:
        time.sleep(0.5)
        png = d.get_screenshot_as_png()
        if _variance(png) > min_variance:
            time.sleep(settle)
            d.execute_script(HIDE_NOTICES)      # the browser's "software WebGL" notice is about the screenshot's
            return d.get_screenshot_as_png()    # own renderer, not the scene
    return png


HIDE_NOTICES = """document.querySelectorAll('[class*="Notification"]').forEach(e => e.style.display = 'none');"""


def _write(png: bytes, path) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(png)
    return out


def screenshot(url: str, path, size=(960, 720), timeout: float = 30.0, min_variance: float = 1e-3,
               settle: float = 1.5) -> Path:
    """The page at ``url`` as ``path`` (PNG), once it has drawn something."""
    d = _driver(size)
    try:
        d.get(url)
        return _write(_drawn(d, timeout, min_variance, settle), path)
    finally:
        d.quit()


def snapshot(scene, path, port: int = 8080, size=(960, 720), step: Optional[int] = None, say=None) -> Path:
    """Serves ``scene``, screenshots it (at ``step``, default the last) and stops the server."""
    k = len(scene.steps) - 1 if step is None else step
    return snapshot_steps(scene, {max(k, 0): path}, port=port, size=size, say=say)[0]


def snapshot_steps(scene, paths: Dict[int, object], port: int = 8080, size=(960, 720), say=None,
                   settle: float = 1.5) -> List[Path]:
    """One PNG per step (``paths``: step -> file) from one server and one browser session: the
    slider is moved on the server side and the page redraws."""
    from .serve import serve, stop

    server, view = serve(scene, port=port, say=say)
    try:
        with progress.heartbeat(say, f"3D view: screenshots of {len(paths)} step(s) in headless Chromium"):
            return _shoot_retrying(server, view, paths, size, settle, say)
    finally:
        stop(server)


#: browser sessions tried before giving up (a renderer starved on a loaded machine times out once)
SESSIONS = 2


def _shoot_retrying(server, view, paths, size, settle: float, say=None) -> List[Path]:
    """:func:`_shoot`, with a new browser session after a timeout, up to :data:`SESSIONS`."""
    from selenium.common.exceptions import TimeoutException

    for attempt in range(1, SESSIONS + 1):
        try:
            return _shoot(server, view, paths, size, settle)
        except TimeoutException as e:
            if attempt == SESSIONS:
                raise
            if say is not None:
                say(f"  3D view: the browser timed out ({str(e).strip().splitlines()[0]}); a new session")


def _shoot(server, view, paths: Dict[int, object], size, settle: float) -> List[Path]:
    """The screenshots of :func:`snapshot_steps` from one browser session on ``server``."""
    d = _driver(size)
    try:
        out = []
        for i, (k, path) in enumerate(sorted(paths.items())):
            view.slider.value = k
            view.show(k)
            if i == 0:
                d.get(f"http://127.0.0.1:{server.get_port()}")
                png = _drawn(d, 30.0, 1e-3, settle)
            else:
                time.sleep(settle)
                d.execute_script(HIDE_NOTICES)
                png = d.get_screenshot_as_png()
            out.append(_write(png, path))
        return out
    finally:
        d.quit()

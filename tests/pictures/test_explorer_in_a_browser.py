"""pb.explorer() in a real browser: JupyterLab on 127.0.0.1 driven by headless Chromium.

A notebook that shows the explorer is run in JupyterLab; the test waits for the
widget's four pictures, moves the roughness slider and switches the model,
and after each change checks from screenshots that the sphere is not blank and
has changed. At a 1100 px window with the file browser open (a notebook area
of about 650 px) and at 800 px nothing of the widget lies outside the output
area, no label or line of text is cut short, and the status line keeps its height.

With ``PB_EXPLORER_SCREENSHOTS=folder`` it writes the widget at 800, 1100 and
1600 px there (docs/rendering-and-plots.md shows them). Needs the ``browser``
group of scripts/install-deps.sh (Debian's chromium and chromium-driver,
selenium, jupyterlab); it takes about half a minute.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")  # a test extra: always there under `make test`
import matplotlib.image as mpimg  # noqa: E402
from selenium import webdriver  # noqa: E402 - the browser group: a missing one fails here, it is not skipped
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

from principled_brdf.explorer_app import _THROUGH_SAMPLES  # noqa: E402 - the 2015 models' first pass

PACKAGE = Path(__import__("principled_brdf").__file__).resolve().parents[1]
TOKEN = "principled-brdf-test"
TIMEOUT = 90.0  # seconds for the server, the kernel and the first pictures on a busy 2-core machine
NOTEBOOK = {
    "cells": [{"cell_type": "code", "execution_count": None, "metadata": {}, "outputs": [],
               "source": ["import principled_brdf as pb\n", "ex = pb.explorer(resolution=128)\n", "ex"]}],
    "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}},
    "nbformat": 4, "nbformat_minor": 5,
}
# what lies outside the output area or is cut short, measured in the page
LAYOUT_FAULTS = """
const output = document.querySelector('.jp-OutputArea-output .widget-box, .jp-OutputArea-output .jupyter-widgets');
const area = output.closest('.jp-OutputArea-output').getBoundingClientRect();
const faults = [];
for (const element of output.querySelectorAll('*')) {
  const box = element.getBoundingClientRect();
  if (box.width === 0 || box.height === 0) continue;
  if (box.right > area.right + 0.5 || box.left < area.left - 0.5)
    faults.push(`${element.className || element.tagName} spans ${box.left}-${box.right}, the area ${area.left}-${area.right}`);
}
for (const label of output.querySelectorAll('.widget-label, .widget-readout, label, .widget-html-content'))
  if (label.scrollWidth > label.clientWidth + 1) faults.push(`label "${label.textContent}" cut short`);
return faults;
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait(condition, what: str, timeout: float = TIMEOUT):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on 127.0.0.1 serving a folder with the explorer's notebook."""
    folder = tmp_path_factory.mktemp("lab")
    (folder / "explorer.ipynb").write_text(json.dumps(NOTEBOOK))
    port = _free_port()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(PACKAGE), os.environ.get("PYTHONPATH")])),
               JUPYTER_CONFIG_DIR=str(folder / "config"), JUPYTER_RUNTIME_DIR=str(folder / "runtime"))
    command = [sys.executable, "-m", "jupyter", "lab", "--no-browser", "--allow-root", "--ip=127.0.0.1",
               f"--port={port}", f"--IdentityProvider.token={TOKEN}", "--expose-app-in-browser",
               f"--ServerApp.root_dir={folder}", "--LabApp.news_url=",
               "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate"]
    log = open(folder / "server.log", "w")
    server = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        def listening():
            try:
                socket.create_connection(("127.0.0.1", port), 0.2).close()
                return True
            except OSError:
                return server.poll() is not None and pytest.fail((folder / "server.log").read_text())
        _wait(listening, "the Jupyter server")
        yield f"http://127.0.0.1:{port}/lab/tree/explorer.ipynb?token={TOKEN}"
    finally:
        server.terminate()
        server.wait(30)
        log.close()


def _browser(width: int, height: int):
    options = webdriver.ChromeOptions()
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     f"--window-size={width},{height}", "--hide-scrollbars"):
        options.add_argument(argument)
    options.binary_location = shutil.which("chromium") or shutil.which("chromium-browser") or ""
    service = webdriver.ChromeService(executable_path=shutil.which("chromedriver"))
    return webdriver.Chrome(options=options, service=service)


def _open_explorer(driver, url: str, *, file_browser: bool):
    driver.get(url)
    _wait(lambda: driver.execute_script(
        "const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;"
        "return !!(w && w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel)"),
        "JupyterLab and the notebook's kernel")
    if not file_browser:
        driver.execute_script("window.jupyterapp.shell.collapseLeft()")
    driver.execute_script("window.jupyterapp.commands.execute('notebook:run-all-cells')")
    _wait(lambda: len(_pictures(driver)) >= 4 and all(
        driver.execute_script("return arguments[0].naturalWidth", image) > 0 for image in _pictures(driver)),
        "the explorer's four pictures")


def _pictures(driver):
    return driver.find_elements(By.CSS_SELECTOR, ".jp-OutputArea-output img.widget-image")


def _sphere_pixels(driver) -> np.ndarray:
    return mpimg.imread(io.BytesIO(_pictures(driver)[0].screenshot_as_png), format="png")[..., :3]


def _changes(driver, action, what: str) -> np.ndarray:
    """Does ``action`` and waits for the sphere's picture to change; returns its pixels."""
    before = _pictures(driver)[0].get_attribute("src")
    action()
    _wait(lambda: _pictures(driver)[0].get_attribute("src") != before, f"the sphere to change after {what}")
    time.sleep(0.3)  # the image element decodes the new PNG
    return _sphere_pixels(driver)


def _samples_shown(driver) -> int:
    """The sphere's samples per pixel in the status line."""
    text = driver.execute_script("return [...document.querySelectorAll('.jp-OutputArea-output .widget-html')]"
                                 ".pop().textContent")
    match = re.search(r"(\d+) samples/px", text)
    return int(match.group(1)) if match else 0


def _status_height(driver) -> float:
    return driver.execute_script(
        "const s = [...document.querySelectorAll('.jp-OutputArea-output .widget-html')].pop();"
        "return s.getBoundingClientRect().height")


def test_the_explorer_works_in_jupyterlab(lab):
    driver = _browser(1100, 900)
    try:
        _open_explorer(driver, lab, file_browser=True)
        first = _sphere_pixels(driver)
        assert first.std() > 0.02, "the sphere is blank"
        assert driver.execute_script(LAYOUT_FAULTS) == []
        status = _status_height(driver)

        slider = driver.find_elements(By.CSS_SELECTOR, ".jp-OutputArea-output .widget-slider")
        roughness = next(s for s in slider if "roughness" in s.text)
        handle = roughness.find_element(By.CSS_SELECTOR, ".noUi-handle")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", handle)
        moved = _changes(driver, lambda: ActionChains(driver).drag_and_drop_by_offset(handle, -45, 0).perform(),
                         "moving the roughness slider")
        assert moved.std() > 0.02 and np.abs(moved - first).max() > 0.05

        model = next(s for s in driver.find_elements(By.CSS_SELECTOR, ".jp-OutputArea-output .widget-dropdown")
                     if "model" in s.text)
        select = Select(model.find_element(By.TAG_NAME, "select"))
        glass = _changes(driver, lambda: select.select_by_visible_text("disney2015"), "switching the model")
        assert glass.std() > 0.02 and np.abs(glass - moved).max() > 0.05
        # while the controls rest, the kernel renders more passes of the sphere into the picture
        _wait(lambda: _samples_shown(driver) >= 3 * _THROUGH_SAMPLES, "the sphere to refine")
        assert driver.execute_script(LAYOUT_FAULTS) == []
        assert _status_height(driver) == status
    finally:
        driver.quit()


@pytest.mark.parametrize("width", [800, 1100, 1600])
def test_nothing_is_clipped_from_800_px_to_wide_screens(lab, width):
    driver = _browser(width, 2400)  # tall: the whole widget in one screenshot
    try:
        _open_explorer(driver, lab, file_browser=width == 1100)
        assert driver.execute_script(LAYOUT_FAULTS) == []
        folder = os.environ.get("PB_EXPLORER_SCREENSHOTS")
        if folder:
            widget = driver.find_element(By.CSS_SELECTOR, ".jp-OutputArea-output .widget-box")
            Path(folder, f"explorer_{width}px.png").write_bytes(widget.screenshot_as_png)
    finally:
        driver.quit()

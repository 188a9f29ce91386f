# SPDX-License-Identifier: MIT
# Shared by the browser tests: headless Chromium through chromedriver (Selenium), on
# loopback only, with the browser's console kept for the checks.
import os
import sys

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
except ImportError as e:  # a clear failure, not a skip: CI installs python3-selenium
    sys.exit(f"browser test: python3-selenium is needed (apt-get install python3-selenium): {e}")

CHROMIUM = os.environ.get("BINOCLE_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("BINOCLE_CHROMEDRIVER", "/usr/bin/chromedriver")


def start_browser(width=1600, height=1100, swiftshader_compositing=False):
    for path, package in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not os.path.exists(path):
            sys.exit(f"browser test: {path} is missing (apt-get install {package})")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # WebGL runs on SwiftShader (no GPU here); the page is composited in software, as
    # Chrome does on a machine without a usable GPU. --use-angle=swiftshader alone would
    # also composite through SwiftShader, a testing-only path that redraws the whole window
    # in emulated shaders for every frame the page changes (50-70 ms of CPU per frame at
    # this size, measured with bench/view_overhead.py --swiftshader-compositing): the cost
    # of this box's emulation, not of the page.
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", f"--window-size={width},{height}",
                "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--proxy-server=127.0.0.1:9"):  # nothing but loopback (bypassed by default) gets out
        options.add_argument(arg)
    if not swiftshader_compositing:
        options.add_argument("--disable-gpu-compositing")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


def console_errors(driver):
    """The page's console errors since the last call."""
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def artifact_dir():
    d = os.environ.get("BINOCLE_TEST_ARTIFACTS", os.path.join(os.getcwd(), "test-artifacts"))
    os.makedirs(d, exist_ok=True)
    return d

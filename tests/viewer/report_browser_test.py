# SPDX-License-Identifier: MIT
# `binocle experiment --report` and `binocle report`, opened from disk in headless
# Chromium with no server: the table (and its sorting), the charts and every test's
# images are there, nothing is fetched from the network, no console errors.
#
# usage: report_browser_test.py BINOCLE_CLI SOURCE_DIR OUT_DIR
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_common import artifact_dir, console_errors, start_browser  # noqa: E402

cli, source_dir, out_dir = sys.argv[1:4]
shutil.rmtree(out_dir, ignore_errors=True)
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what, flush=True)
    if not condition:
        failures.append(what)


experiment = os.path.join(source_dir, "configs/experiments/e1.yaml")
run = subprocess.run([cli, "experiment", experiment, "--tests", "3,7,10", "--out", out_dir, "--report", "--quiet"],
                     capture_output=True, text=True)
check(run.returncode == 0, f"experiment --report runs ({run.stderr.strip()[-300:]})")
report = os.path.join(out_dir, "report.html")
check(os.path.exists(report), "experiment --report writes report.html")
os.remove(report)
again = subprocess.run([cli, "report", out_dir], capture_output=True, text=True)
check(again.returncode == 0 and again.stdout.strip() == report, f"binocle report DIR writes it again ({again.stdout.strip()})")
bad = subprocess.run([cli, "report", os.path.join(out_dir, "test_3")], capture_output=True, text=True)
check(bad.returncode != 0 and "results.json" in bad.stderr, f"a folder without results is refused: {bad.stderr.strip()}")

html = open(report, encoding="utf-8").read()
check(not re.search(r"(src|href)=\"(https?:)?//", html) and "@import" not in html and "url(http" not in html,
      "the report references nothing on the network")

# Away from the output folder: the report must stand alone.
alone = os.path.join(out_dir, "moved")
os.makedirs(alone)
moved = os.path.join(alone, "report.html")
shutil.copy(report, moved)

driver = start_browser(1400, 1000)
try:
    driver.get("file://" + moved)
    rows = driver.execute_script("return Array.from(document.querySelectorAll('#results tbody tr')).map(r => r.dataset.test)")
    check(rows == ["3", "7", "10"], f"the table has a row per test ({rows})")
    heads = driver.execute_script("return Array.from(document.querySelectorAll('#results thead th')).map(h => h.textContent)")
    check(any(h.startswith("η3D") for h in heads) and any(h.startswith("FF") for h in heads), f"the table's columns: {heads}")
    eta = heads.index(next(h for h in heads if h.startswith("η3D")))
    values = lambda: driver.execute_script(  # noqa: E731
        f"return Array.from(document.querySelectorAll('#results tbody tr')).map(r => parseFloat(r.cells[{eta}].dataset.sort))")
    driver.execute_script(f"document.querySelectorAll('#results thead th')[{eta}].click()")
    ascending = values()
    driver.execute_script(f"document.querySelectorAll('#results thead th')[{eta}].click()")
    descending = values()
    check(ascending == sorted(ascending) and descending == sorted(ascending, reverse=True),
          f"clicking η3D sorts the table ({ascending} / {descending})")
    charts = driver.execute_script("return Array.from(document.querySelectorAll('figure.chart')).map(f => f.id)")
    check("chart-eta_3d_vs_ff" in charts and "chart-eta_3d_bars" in charts, f"the charts are inline ({charts})")
    images = driver.execute_script(
        "return Array.from(document.querySelectorAll('section.test img')).map(i => [i.alt, i.naturalWidth, i.src.slice(0, 22)])")
    check(len(images) == 12, f"4 images per test ({len(images)})")
    check(all(w > 0 and src.startswith("data:image/png;base64") for _, w, src in images),
          "every image is inlined and decodes: " + ", ".join(a for a, w, _ in images if w == 0))
    # What the reading took: in words under each test, and outlined in red (BGR 40, 40, 220)
    # over its front view, so that every figure can be checked by eye.
    readings = driver.execute_script(
        "return Array.from(document.querySelectorAll('section.test')).map(s => "
        "(s.querySelector('p.reading') || {textContent: ''}).textContent)")
    check(len(readings) == 3 and all("X′ = " in r and "Z′ = " in r for r in readings),
          f"each test says what was read as the panel ({readings})")
    outlined = driver.execute_script("""
        return Array.from(document.querySelectorAll('section.test img'))
          .filter(i => i.alt.endsWith('front view (XZ)')).map(i => {
            const c = document.createElement('canvas');
            c.width = i.naturalWidth; c.height = i.naturalHeight;
            const g = c.getContext('2d');
            g.drawImage(i, 0, 0);
            const d = g.getImageData(0, 0, c.width, c.height).data;
            let n = 0;
            for (let k = 0; k < d.length; k += 4)
              if (d[k] > 200 && d[k] < 240 && d[k + 1] > 30 && d[k + 1] < 60 && d[k + 2] > 30 && d[k + 2] < 60) ++n;
            return n; })""")
    check(len(outlined) == 3 and all(n > 200 for n in outlined),
          f"the panel's cells are outlined over every front view (red pixels: {outlined})")
    provenance = driver.find_element("id", "provenance").get_attribute("textContent")
    check("binocle" in provenance and "OpenCV" in provenance and "sgbm" in provenance and "matcher:" in provenance,
          "the rig and the software versions are stated")
    driver.save_screenshot(os.path.join(artifact_dir(), "report.png"))
    errors = console_errors(driver)
    check(not errors, f"no console errors ({errors})")
finally:
    driver.quit()

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")

"""The 3D Tiles viewer in headless Chromium (issue 40 item 4): a synthetic city of 4 buildings through `hsr city`
and `hsr tiles --png`; the page must load the tileset's one content with its 4 buildings and no error (its
title says so), and the screenshot must show them (several colours, a fair share of non-background pixels,
roof red among them).

Usage: tiles3d_browser_test.py HSR_CLI TMP_DIR. Exits 77 (CTest: skipped) when Chromium is not installed.
"""
import html
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "report"))
import pngread  # noqa: E402
from browser_test import ViewParser, chromium, fail, run_browser  # noqa: E402

SKIP = 77


def main():
    cli, tmp = sys.argv[1], sys.argv[2]
    browser = chromium()
    if not browser:
        print("SKIP: Chromium not installed (Debian package chromium; scripts/install-deps.sh installs it)")
        sys.exit(SKIP)
    os.makedirs(tmp, exist_ok=True)
    tile = os.path.join(tmp, "tile")
    subprocess.run([cli, "-q", "synth", "city", "--buildings", "4", "--seed", "3", "-o", tile], check=True)
    seq = os.path.join(tmp, "city.city.jsonl")
    subprocess.run([cli, "-q", "city", os.path.join(tile, "tile.las"), "-o", seq, "--footprints",
                    os.path.join(tile, "footprints.geojson"), "--id-field", "id", "-j", "2"], check=True)
    out, png = os.path.join(tmp, "tiles"), os.path.join(tmp, "tiles.png")
    if os.path.exists(png):
        os.remove(png)
    subprocess.run([cli, "-q", "tiles", seq, "-o", out, "--png", png], check=True)
    profile = tempfile.mkdtemp(prefix="hsr-tiles3d-test-")
    r = run_browser(browser, "file://" + os.path.join(out, "index.html"), ["--dump-dom", "--allow-file-access-from-files"], profile)
    p = ViewParser()
    p.feed(r.stdout)
    if not p.done:
        fail("the viewer did not finish (no data-hsr-done); title %r; stderr tail:\n%s" % (p.title, r.stderr[-2000:]))
    if p.title.strip() != "hsr: 3D tiles 1/1 contents, 4 buildings, 0 errors":
        fail("title %r; errors: %s" % (p.title, p.errors))
    if not os.path.exists(png):
        fail("hsr tiles --png wrote no screenshot")
    img = pngread.read_png(png)
    colours, drawn = pngread.distinct_colours(img), pngread.non_background_fraction(img)
    print("viewer: %s; screenshot %d colours, %.1f%% drawn" % (p.title.strip(), colours, 100 * drawn))
    if colours < 16 or drawn < 0.01:
        fail("the screenshot is (nearly) blank: %d colours, %.2f%% drawn" % (colours, 100 * drawn))
    rgb = img[..., :3].astype(int)
    reddish = int(((rgb[..., 0] > rgb[..., 1] + 40) & (rgb[..., 0] > rgb[..., 2] + 40)).sum())
    if reddish < 50:
        fail("no roof (red) in the screenshot: %d reddish pixels" % reddish)
    print("saved " + png)
    # A click on a building shows its id and attributes (index.html#click clicks where the first one is drawn).
    r = run_browser(browser, "file://" + os.path.join(out, "index.html") + "#click", ["--dump-dom", "--allow-file-access-from-files"], profile)
    m = re.search(r'<div id="info">(.*?)</div>', r.stdout, re.S)
    info = html.unescape(m.group(1)) if m else ""
    print("click: " + info[:160])
    if not re.match(r"B\d{4} \{", info) or '"b3_h_dak_70p"' not in info or '"hsr_validity_lod22"' not in info:
        fail("a click on a building did not show its id and attributes: %r" % info[:300])


if __name__ == "__main__":
    main()

"""End-to-end browser test of the visual report (issue "Python module and visual reports of every stage").

Reconstructs a synth scan with `hsr reconstruct --html --png`, opens the report in headless Chromium and checks
that every stage view rendered (the page marks each view data-rendered="1" with the number of non-background
pixels it read back from WebGL) without script or console errors; then takes a screenshot of the whole page
and checks, on the PNG itself, that no view is blank (each view's rectangle holds several colours and a
fair share of non-background pixels); finally checks `hsr render` on the output mesh.

Usage: browser_test.py HSR_CLI TMP_DIR. Exits 77 (CTest: skipped) when Chromium is not installed.
"""
import html.parser
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pngread  # noqa: E402

SKIP = 77
EXPECTED_VIEWS = ["input", "planes", "visibility", "levels", "polygons", "partition", "mesh"]


def chromium():
    for name in (os.environ.get("HSR_CHROMIUM", ""), "chromium", "chromium-browser"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def run_browser(browser, url, extra, profile):
    cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run", "--disable-background-networking",
           "--disable-component-update", "--disable-sync", "--hide-scrollbars", "--force-device-scale-factor=1",
           "--enable-logging=stderr", "--v=0", "--user-data-dir=" + profile, "--virtual-time-budget=30000"]
    return subprocess.run(cmd + extra + [url], capture_output=True, text=True, timeout=300)


class ViewParser(html.parser.HTMLParser):
    """Collects the title, the data-* attributes of every view element and the error list."""

    def __init__(self):
        super().__init__()
        self.views, self.title, self.errors, self.done = {}, "", "", False
        self._in = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "data-view" in a:
            self.views[a["data-view"]] = a
        if tag == "body" and a.get("data-hsr-done") == "1":
            self.done = True
        if tag in ("title",) or a.get("id") == "hsr-errors":
            self._in = tag if tag == "title" else "errors"

    def handle_endtag(self, tag):
        if tag in ("title", "pre"):
            self._in = None

    def handle_data(self, data):
        if self._in == "title":
            self.title += data
        elif self._in == "errors":
            self.errors += data


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main():
    cli, tmp = sys.argv[1], sys.argv[2]
    browser = chromium()
    if not browser:
        print("SKIP: Chromium not installed (Debian package chromium; scripts/install-deps.sh installs it)")
        sys.exit(SKIP)
    os.makedirs(tmp, exist_ok=True)
    profile = tempfile.mkdtemp(prefix="hsr-browser-test-")
    try:
        scan = os.path.join(tmp, "house")
        subprocess.run([cli, "-q", "synth", "house", "-o", scan, "--points", "20000"], check=True)
        page, mesh, still = os.path.join(tmp, "report.html"), os.path.join(tmp, "house.obj"), os.path.join(tmp, "house.png")
        for f in (page, still):
            if os.path.exists(f):
                os.remove(f)
        subprocess.run([cli, "-q", "reconstruct", os.path.join(scan, "points.ply"), "-o", mesh,
                        "--html", page, "--png", still], check=True)

        # 1. Every view rendered, no script/console error.
        r = run_browser(browser, "file://" + page, ["--dump-dom"], profile)
        p = ViewParser()
        p.feed(r.stdout)
        if not p.done:
            fail("the page did not finish (no data-hsr-done); title %r; stderr tail:\n%s" % (p.title, r.stderr[-2000:]))
        if p.errors.strip():
            fail("the page reported errors:\n" + p.errors)
        console_errors = [l for l in r.stderr.splitlines() if "CONSOLE" in l and ("Uncaught" in l or ":ERROR:CONSOLE" in l)]
        if console_errors:
            fail("console errors:\n" + "\n".join(console_errors))
        expected_title = "hsr: rendered %d/%d views, 0 errors" % (len(EXPECTED_VIEWS), len(EXPECTED_VIEWS))
        if p.title.strip() != expected_title:
            fail("title %r, expected %r" % (p.title, expected_title))
        if sorted(p.views) != sorted(EXPECTED_VIEWS):
            fail("views %s, expected %s" % (sorted(p.views), sorted(EXPECTED_VIEWS)))
        rects = {}
        for name, attrs in p.views.items():
            if attrs.get("data-rendered") != "1":
                fail("view %s did not render" % name)
            x, y, w, h = (int(v) for v in attrs["data-rect"].split(","))
            drawn = int(attrs["data-nonbackground"])
            if drawn < 0.005 * w * h:  # WebGL read-back: the view drew (almost) nothing
                fail("view %s is blank in WebGL (%d of %d pixels drawn)" % (name, drawn, w * h))
            rects[name] = (x, y, w, h)
        print("views rendered: " + ", ".join("%s %s px" % (n, p.views[n]["data-nonbackground"]) for n in EXPECTED_VIEWS))

        # 2. Screenshot of the whole page; every view's rectangle in the PNG is not blank.
        bottom = max(y + h for (x, y, w, h) in rects.values()) + 40
        right = max(x + w for (x, y, w, h) in rects.values()) + 40
        shot = os.path.join(tmp, "report.png")
        if os.path.exists(shot):
            os.remove(shot)
        run_browser(browser, "file://" + page, ["--screenshot=" + shot, "--window-size=%d,%d" % (right, bottom)], profile)
        if not os.path.exists(shot):
            fail("Chromium wrote no screenshot")
        img = pngread.read_png(shot)
        if pngread.distinct_colours(img) < 2:
            fail("the screenshot is a single colour")
        for name, (x, y, w, h) in rects.items():
            crop = img[y:y + h, x:x + w]
            colours, drawn = pngread.distinct_colours(crop), pngread.non_background_fraction(crop)
            print("screenshot view %-10s %4d colours, %.1f%% drawn" % (name, colours, 100 * drawn))
            if colours < 8 or drawn < 0.005:
                fail("view %s is blank in the screenshot (%d colours, %.2f%% drawn)" % (name, colours, 100 * drawn))
        print("saved " + shot)

        # 3. The stills: --png of reconstruct, and `hsr render`.
        for png in (still, os.path.join(tmp, "render.png")):
            if png != still:
                if os.path.exists(png):
                    os.remove(png)
                subprocess.run([cli, "-q", "render", mesh, "-o", png, "--width", "640", "--height", "480"], check=True)
            img = pngread.read_png(png)
            drawn = pngread.non_background_fraction(img)
            print("%s: %dx%d, %d colours, %.1f%% drawn" % (png, img.shape[1], img.shape[0], pngread.distinct_colours(img), 100 * drawn))
            if pngread.distinct_colours(img) < 8 or drawn < 0.02:
                fail(png + " is blank")
        indoor_view(cli, tmp)
        print("PASS")
    finally:
        shutil.rmtree(profile, ignore_errors=True)


def write_obj(path, boxes):
    """Boxes (x0, x1, y0, y1, z0, z1, outward) as one OBJ: outward boxes face out, the others are cavities
    (their faces turned into the box), so the box minus a cavity is a closed solid oriented outward."""
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    with open(path, "w") as f:
        for k, (x0, x1, y0, y1, z0, z1, out) in enumerate(boxes):
            for z in (z0, z1):
                for y in (y0, y1):
                    for x in (x0, x1):
                        f.write("v %g %g %g\n" % (x, y, z))
        for k, b in enumerate(boxes):
            for q in quads:  # corner index = x + 2 y + 4 z; these loops face outward
                q = q if b[6] else q[::-1]
                f.write("f " + " ".join(str(8 * k + i + 1) for i in q) + "\n")


def indoor_view(cli, tmp):
    """Issue 25: the cutaway shows what a room holds. A table-like block floating in a room's air is hidden
    from outside (the pictures of the room with and without it are the same) and seen in the cutaway (they
    differ); `hsr render` picks the cutaway by itself for points scanned from inside."""
    room, empty = os.path.join(tmp, "room_block.obj"), os.path.join(tmp, "room_empty.obj")
    write_obj(empty, [(0, 8, 0, 6, 0, 3, True)])
    write_obj(room, [(0, 8, 0, 6, 0, 3, True), (2, 4.4, 1.5, 3, 0.4, 0.78, False)])
    pics = {}
    for view in ("outside", "cutaway"):
        for name, mesh in (("block", room), ("empty", empty)):
            png = os.path.join(tmp, "room_%s_%s.png" % (name, view))
            subprocess.run([cli, "-q", "render", mesh, "-o", png, "--width", "480", "--height", "360", "--view", view],
                           check=True)
            pics[(name, view)] = pngread.read_png(png)
    def differing(a, b):
        return float((abs(a.astype(int) - b.astype(int)).sum(axis=2) > 24).mean())
    out, cut = differing(pics[("block", "outside")], pics[("empty", "outside")]), \
        differing(pics[("block", "cutaway")], pics[("empty", "cutaway")])
    print("room with / without its block: %.2f%% of the pixels differ from outside, %.2f%% in the cutaway"
          % (100 * out, 100 * cut))
    if out > 0.001:
        fail("from outside the block inside the room shows (%.2f%% of the pixels differ)" % (100 * out))
    if cut < 0.003:  # the block: 0.6 % of a 480 x 360 picture
        fail("the cutaway does not show the block inside the room (%.2f%% of the pixels differ)" % (100 * cut))
    scan = os.path.join(tmp, "room")
    subprocess.run([cli, "-q", "synth", "room", "-o", scan, "--points", "20000"], check=True)
    auto, forced = os.path.join(tmp, "room_auto.png"), os.path.join(tmp, "room_forced.png")
    for png, extra in ((auto, []), (forced, ["--view", "cutaway"])):
        subprocess.run([cli, "-q", "render", room, os.path.join(scan, "points.ply"), "-o", png, "--width", "480",
                        "--height", "360"] + extra, check=True)
    if differing(pngread.read_png(auto), pngread.read_png(forced)) > 0.001:
        fail("hsr render did not choose the cutaway for points scanned from inside")
    print("hsr render chose the cutaway for the room's scan")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Deterministic procedural textures for the tgnav scenes (models/textures/*.png).

Texture is the experimental variable of the scenes: the visual odometry can only track what the
camera sees, so textured surfaces must be rich in FAST/ORB corners at several scales, while
texture-poor surfaces are plain materials in the MJCF (no image at all). Every image here is
drawn with numpy from a fixed seed (no fonts, no noise fields), so reruns give the same pixels:

    /usr/bin/python3 scripts/make_textures.py        # rewrites models/textures/*.png

Images are 256x256 (MuJoCo cube textures need square faces; each face of a box shows one whole
image, stretched to the face's size). The scenes use type="cube" textures on boxes. MuJoCo 2.2
shows a cube face image upright on the -y face (filedown), turned 180 degrees on +y (fileup), 90
degrees counter-clockwise on -x (fileleft) and 90 degrees clockwise on +x (fileright). So every
texture is also written pre-rotated, and a scene that wants it upright on all four vertical faces
names the variants per face:

    <texture name="T" type="cube" filedown="T.png" fileup="T_180.png" fileleft="T_cw.png"
             fileright="T_ccw.png" filefront="T.png" fileback="T.png"/>
"""
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
from matplotlib.path import Path  # noqa: E402

SIZE = 256
OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "models", "textures")

# Pixel centres, shared by every shape mask.
_YY, _XX = np.mgrid[0:SIZE, 0:SIZE].astype(np.float64) + 0.5

# Saturated, mutually contrasting colours (RGB in 0..1) for labels, books, bins and paintings.
PALETTE = np.array([
    [0.85, 0.12, 0.10], [0.95, 0.55, 0.05], [0.98, 0.85, 0.10], [0.20, 0.60, 0.20],
    [0.05, 0.35, 0.15], [0.10, 0.45, 0.80], [0.05, 0.15, 0.45], [0.55, 0.20, 0.65],
    [0.95, 0.95, 0.92], [0.08, 0.08, 0.08], [0.50, 0.28, 0.12], [0.00, 0.65, 0.70],
    [0.90, 0.45, 0.60], [0.60, 0.62, 0.65], [0.35, 0.35, 0.38], [0.75, 0.80, 0.20],
])


def canvas(rgb):
    img = np.empty((SIZE, SIZE, 3))
    img[:] = rgb
    return img


def rect(img, x0, y0, x1, y1, rgb):
    x0, x1 = sorted((int(round(x0)), int(round(x1))))
    y0, y1 = sorted((int(round(y0)), int(round(y1))))
    x0, y0 = max(x0, 0), max(y0, 0)
    x1, y1 = min(x1, SIZE), min(y1, SIZE)
    if x1 > x0 and y1 > y0:
        img[y0:y1, x0:x1] = rgb


def frame(img, x0, y0, x1, y1, width, rgb):
    rect(img, x0, y0, x1, y0 + width, rgb)
    rect(img, x0, y1 - width, x1, y1, rgb)
    rect(img, x0, y0, x0 + width, y1, rgb)
    rect(img, x1 - width, y0, x1, y1, rgb)


def ellipse(img, cx, cy, rx, ry, rgb, angle=0.0):
    c, s = np.cos(angle), np.sin(angle)
    dx, dy = _XX - cx, _YY - cy
    u, v = (c * dx + s * dy) / rx, (-s * dx + c * dy) / ry
    img[u * u + v * v <= 1.0] = rgb


def polygon(img, pts, rgb):
    path = Path(np.asarray(pts, dtype=np.float64))
    inside = path.contains_points(np.column_stack([_XX.ravel(), _YY.ravel()]))
    img[inside.reshape(SIZE, SIZE)] = rgb


def line(img, x0, y0, x1, y1, width, rgb):
    """A straight stroke as a thin rotated rectangle."""
    d = np.array([x1 - x0, y1 - y0], dtype=np.float64)
    n = np.array([-d[1], d[0]]) / max(np.hypot(*d), 1e-9) * width / 2.0
    polygon(img, [(x0 + n[0], y0 + n[1]), (x1 + n[0], y1 + n[1]),
                  (x1 - n[0], y1 - n[1]), (x0 - n[0], y0 - n[1])], rgb)


class Glyphs:
    """Text-like marks: a fixed set of random 3x5 'letters' (blocky, corner-rich)."""

    def __init__(self, seed=7, count=32):
        rng = np.random.default_rng(seed)
        self.glyphs = []
        while len(self.glyphs) < count:
            g = rng.random((5, 3)) < 0.55
            if 5 <= g.sum() <= 12 and g.any(axis=0).all() and g.any(axis=1).sum() >= 4:
                self.glyphs.append(g)

    @staticmethod
    def letter(img, g, x, y, cell, rgb):
        for r in range(5):
            for c in range(3):
                if g[r, c]:
                    x0, y0 = x + c * cell, y + r * cell
                    rect(img, x0, y0, x0 + cell, y0 + cell, rgb)

    def word(self, img, x, y, n, cell, rgb, rng):
        """n letters of cell-pixel blocks starting at (x, y); returns the x after the word."""
        for _ in range(n):
            self.letter(img, self.glyphs[rng.integers(len(self.glyphs))], x, y, cell, rgb)
            x += 4 * cell
        return x

    def text(self, img, x0, y0, x1, cell, rgb, rng, max_words=20):
        """A line of words from x0 to at most x1 (5*cell tall)."""
        x = x0
        for _ in range(max_words):
            n = int(rng.integers(2, 7))
            if x + n * 4 * cell > x1:
                break
            x = self.word(img, x, y0, n, cell, rgb, rng) + 2 * cell

    def vertical_text(self, img, x0, y0, y1, cell, rgb, rng):
        """Letters stacked down a book spine."""
        y = y0
        while y + 5 * cell <= y1:
            self.letter(img, self.glyphs[rng.integers(len(self.glyphs))], x0, y, cell, rgb)
            y += 6 * cell


GLYPHS = Glyphs()


def barcode(img, x0, y0, x1, y1, rng):
    rect(img, x0 - 2, y0 - 2, x1 + 2, y1 + 2, (1, 1, 1))
    x = x0
    while x < x1:
        w = int(rng.integers(1, 4))
        if rng.random() < 0.55:
            rect(img, x, y0, min(x + w, x1), y1, (0.02, 0.02, 0.02))
        x += w


def label(img, x0, y0, x1, y1, rng, paper=(0.97, 0.96, 0.92), ink=(0.05, 0.05, 0.08)):
    """A printed paper label: title, text lines and sometimes a barcode."""
    rect(img, x0, y0, x1, y1, paper)
    frame(img, x0, y0, x1, y1, 1, (0.3, 0.3, 0.3))
    y = y0 + 4
    title = 2 if x1 - x0 >= 60 and y1 - y0 >= 30 else 1
    GLYPHS.text(img, x0 + 4, y, x1 - 4, title, ink, rng, max_words=3)
    y += 7 * title
    while y + 6 < y1 - (18 if y1 - y0 > 50 else 0):
        GLYPHS.text(img, x0 + 4, y, x1 - 4 - int(rng.integers(0, (x1 - x0) // 3 + 1)), 1, ink, rng)
        y += 8
    if y1 - y0 > 50:
        barcode(img, x0 + 6, y1 - 16, x0 + 6 + int((x1 - x0) * 0.6), y1 - 5, rng)


def wood(img, x0, y0, x1, y1, base, rng, horizontal=True):
    """A board: flat base colour, darker grain streaks and the odd knot."""
    rect(img, x0, y0, x1, y1, base)
    dark = np.clip(np.asarray(base) * 0.72, 0, 1)
    length = (x1 - x0) if horizontal else (y1 - y0)
    across = (y1 - y0) if horizontal else (x1 - x0)
    for _ in range(int(across // 4)):
        a = rng.uniform(0, across)
        s0 = rng.uniform(0, length * 0.6)
        s1 = s0 + rng.uniform(length * 0.2, length * 0.7)
        w = rng.uniform(0.8, 1.8)
        if horizontal:
            line(img, x0 + s0, y0 + a, x0 + s1, y0 + a + rng.uniform(-2, 2), w, dark)
        else:
            line(img, x0 + a, y0 + s0, x0 + a + rng.uniform(-2, 2), y0 + s1, w, dark)
    for _ in range(int(rng.integers(0, 3))):
        cx = rng.uniform(x0 + 6, x1 - 6)
        cy = rng.uniform(y0 + 4, y1 - 4)
        r = rng.uniform(3, 7)
        rx, ry = (r * 1.6, r) if horizontal else (r, r * 1.6)
        ellipse(img, cx, cy, rx + 2, ry + 2, dark)
        ellipse(img, cx, cy, rx, ry, np.clip(np.asarray(base) * 0.5, 0, 1))
        ellipse(img, cx, cy, rx * 0.45, ry * 0.45, np.clip(np.asarray(base) * 0.3, 0, 1))


# ---------------------------------------------------------------------------------------------
# The textures
# ---------------------------------------------------------------------------------------------

def crate_wood(seed, base, stencil_rgb):
    """A wooden crate face: planks, a frame, a diagonal brace, knots, nails, stencil text."""
    rng = np.random.default_rng(seed)
    img = canvas(np.asarray(base) * 0.45)
    n = 6
    h = SIZE / n
    for i in range(n):
        tint = np.clip(np.asarray(base) * rng.uniform(0.85, 1.1), 0, 1)
        wood(img, 0, i * h + 1.5, SIZE, (i + 1) * h - 1.5, tint, rng)
    frame_rgb = np.clip(np.asarray(base) * 0.8, 0, 1)
    for (x0, y0, x1, y1) in [(0, 0, SIZE, 22), (0, SIZE - 22, SIZE, SIZE)]:
        wood(img, x0, y0, x1, y1, frame_rgb, rng)
    for (x0, y0, x1, y1) in [(0, 0, 22, SIZE), (SIZE - 22, 0, SIZE, SIZE)]:
        wood(img, x0, y0, x1, y1, frame_rgb, rng, horizontal=False)
    for x0, y0, x1, y1 in [(0, 0, SIZE, 22), (0, SIZE - 22, SIZE, SIZE), (0, 0, 22, SIZE),
                           (SIZE - 22, 0, SIZE, SIZE)]:
        frame(img, x0, y0, x1, y1, 1, np.asarray(base) * 0.4)
    # Diagonal brace.
    polygon(img, [(22, SIZE - 40), (40, SIZE - 22), (SIZE - 22, 40), (SIZE - 40, 22)],
            np.clip(np.asarray(base) * 0.9, 0, 1))
    line(img, 22, SIZE - 40, SIZE - 40, 22, 1.5, np.asarray(base) * 0.4)
    line(img, 40, SIZE - 22, SIZE - 22, 40, 1.5, np.asarray(base) * 0.4)
    # Nails.
    for x in (11, SIZE - 11):
        for y in np.linspace(11, SIZE - 11, 6):
            ellipse(img, x, y, 2.2, 2.2, (0.12, 0.12, 0.12))
    # Stencilled marks: a word block, an arrow pair, a framed code.
    GLYPHS.text(img, 40, 60, 200, 4, stencil_rgb, rng, max_words=2)
    for ax in (150, 180):
        polygon(img, [(ax, 150), (ax + 12, 132), (ax + 24, 150)], stencil_rgb)
        rect(img, ax + 8, 150, ax + 16, 172, stencil_rgb)
    label(img, 40, 150, 130, 205, rng)
    return img


def cardboard(seed):
    """A shipping carton: kraft board, tape, a shipping label, handling icons, big numbers."""
    rng = np.random.default_rng(seed)
    kraft = np.array([0.72, 0.55, 0.36])
    img = canvas(kraft)
    # Flap seams and corrugation hints.
    rect(img, 0, 120, SIZE, 124, kraft * 0.75)
    for x in range(0, SIZE, 32):
        rect(img, x, 0, x + 1, 120, kraft * 0.9)
    rect(img, 112, 0, 144, SIZE, (0.80, 0.70, 0.50))   # tape
    frame(img, 112, -2, 144, SIZE + 2, 1, kraft * 0.6)
    label(img, 150, 20, 245, 110, rng)
    label(img, 14, 140, 100, 190, rng, paper=(0.98, 0.90, 0.20))
    # Handling icons: umbrella, glass, arrows.
    ink = (0.10, 0.10, 0.12)
    frame(img, 14, 20, 100, 60, 2, ink)
    ellipse(img, 34, 40, 12, 8, ink)
    rect(img, 33, 40, 36, 56, ink)
    polygon(img, [(55, 26), (71, 26), (67, 44), (59, 44)], ink)
    rect(img, 62, 44, 64, 54, ink)
    rect(img, 56, 53, 70, 56, ink)
    polygon(img, [(78, 44), (86, 28), (94, 44)], ink)
    rect(img, 84, 44, 88, 56, ink)
    # Big stencil number and a printed red stamp.
    GLYPHS.word(img, 150, 150, 3, 6, ink, rng)
    frame(img, 20, 205, 110, 245, 3, (0.75, 0.08, 0.08))
    GLYPHS.text(img, 28, 215, 104, 3, (0.75, 0.08, 0.08), rng, max_words=2)
    return img


def shelf_books(seed):
    """A bookcase: dark boards, four tiers of spines of varied widths, colours and titles."""
    rng = np.random.default_rng(seed)
    board = np.array([0.30, 0.20, 0.12])
    img = canvas(np.array([0.12, 0.09, 0.07]))
    tiers = 4
    th = SIZE / tiers
    for t in range(tiers):
        top, bottom = t * th + 8, (t + 1) * th - 6
        x = 10
        while x < SIZE - 12:
            w = int(rng.integers(6, 20))
            if rng.random() < 0.08:
                x += int(rng.integers(6, 16))   # a gap
                continue
            h = (bottom - top) * rng.uniform(0.65, 0.98)
            col = PALETTE[rng.integers(len(PALETTE))]
            x1 = min(x + w, SIZE - 10)
            rect(img, x, bottom - h, x1, bottom, col)
            mark = PALETTE[9] if col.mean() > 0.45 else PALETTE[8]
            for _ in range(int(rng.integers(1, 3))):
                yb = bottom - h * rng.uniform(0.1, 0.9)
                rect(img, x, yb, x1, yb + rng.integers(2, 4), mark)
            if w >= 9:
                GLYPHS.vertical_text(img, x + (w - 3) // 2, bottom - h + 6, bottom - 8, 1, mark,
                                     rng)
            rect(img, x1 - 1, bottom - h, x1, bottom, col * 0.5)
            x = x1 + 1
        rect(img, 0, bottom, SIZE, bottom + 6, board)
        rect(img, 0, bottom + 6, SIZE, bottom + 7, board * 0.5)
    rect(img, 0, 0, 10, SIZE, board)
    rect(img, SIZE - 10, 0, SIZE, SIZE, board)
    rect(img, 0, 0, SIZE, 8, board)
    return img


def shelf_bins(seed):
    """A storage rack: steel uprights, coloured bins with label cards, small boxes."""
    rng = np.random.default_rng(seed)
    steel = np.array([0.35, 0.45, 0.60])
    img = canvas(np.array([0.18, 0.18, 0.20]))
    tiers = 3
    th = SIZE / tiers
    for t in range(tiers):
        top, bottom = t * th + 6, (t + 1) * th - 8
        x = 12
        while x < SIZE - 20:
            w = int(rng.integers(30, 62))
            x1 = min(x + w, SIZE - 12)
            if x1 - x < 20:
                break
            if rng.random() < 0.7:
                col = PALETTE[rng.choice([0, 1, 2, 3, 5, 11])]
                h = (bottom - top) * rng.uniform(0.55, 0.8)
                rect(img, x, bottom - h, x1, bottom, col)
                rect(img, x, bottom - h, x1, bottom - h + 4, col * 0.7)
                label(img, x + 5, bottom - h * 0.62, x1 - 5, bottom - h * 0.62 + 20, rng)
            else:
                kraft = np.array([0.70, 0.53, 0.34]) * rng.uniform(0.85, 1.1)
                yb = bottom
                while yb - top > 20:
                    bh = rng.uniform(14, 28)
                    bw = (x1 - x) * rng.uniform(0.6, 1.0)
                    rect(img, x, yb - bh, x + bw, yb, np.clip(kraft, 0, 1))
                    rect(img, x + bw * 0.3, yb - bh, x + bw * 0.4, yb, np.clip(kraft * 1.15, 0, 1))
                    frame(img, x, yb - bh, x + bw, yb, 1, kraft * 0.6)
                    yb -= bh + 1
            x = x1 + int(rng.integers(3, 9))
        rect(img, 0, bottom, SIZE, bottom + 8, (0.90, 0.50, 0.10))   # orange beam
        rect(img, 0, bottom + 7, SIZE, bottom + 8, (0.40, 0.20, 0.05))
    rect(img, 0, 0, 10, SIZE, steel)
    rect(img, SIZE - 10, 0, SIZE, SIZE, steel)
    for y in range(6, SIZE, 12):
        rect(img, 3, y, 7, y + 5, steel * 0.3)
        rect(img, SIZE - 7, y, SIZE - 3, y + 5, steel * 0.3)
    return img


def poster_blocks(seed):
    """Abstract blocks at three scales, outlined (Mondrian-like but busy)."""
    rng = np.random.default_rng(seed)
    img = canvas((0.93, 0.92, 0.88))
    for count, lo, hi in [(8, 50, 110), (30, 16, 50), (90, 4, 16)]:
        for _ in range(count):
            w, h = rng.uniform(lo, hi, 2)
            x, y = rng.uniform(-w / 2, SIZE - w / 2), rng.uniform(-h / 2, SIZE - h / 2)
            rect(img, x, y, x + w, y + h, PALETTE[rng.integers(len(PALETTE))])
            if lo >= 16:
                frame(img, x, y, x + w, y + h, 2, (0.05, 0.05, 0.05))
    return img


def poster_blobs(seed):
    """Discs, ellipses and triangles of many sizes on a two-tone ground."""
    rng = np.random.default_rng(seed)
    img = canvas((0.15, 0.25, 0.40))
    polygon(img, [(0, SIZE), (SIZE, 60), (SIZE, SIZE)], (0.90, 0.85, 0.70))
    for count, lo, hi in [(6, 25, 45), (25, 8, 25), (120, 2, 8)]:
        for _ in range(count):
            col = PALETTE[rng.integers(len(PALETTE))]
            x, y = rng.uniform(0, SIZE, 2)
            r = rng.uniform(lo, hi)
            kind = rng.random()
            if kind < 0.45:
                ellipse(img, x, y, r, r * rng.uniform(0.4, 1.0), col, rng.uniform(0, np.pi))
            elif kind < 0.8:
                a = rng.uniform(0, 2 * np.pi)
                pts = [(x + r * np.cos(a + k * 2.1), y + r * np.sin(a + k * 2.1)) for k in range(3)]
                polygon(img, pts, col)
            else:
                rect(img, x - r, y - r * 0.5, x + r, y + r * 0.5, col)
    return img


def painting_frame(img):
    """A dark wooden frame with a gilt inner edge and carved beads."""
    gold = np.array([0.80, 0.65, 0.25])
    frame(img, 0, 0, SIZE, SIZE, 18, (0.25, 0.15, 0.08))
    frame(img, 18, 18, SIZE - 18, SIZE - 18, 4, gold)
    frame(img, 22, 22, SIZE - 22, SIZE - 22, 2, (0.10, 0.07, 0.04))
    for k in range(0, SIZE, 24):   # carved beads on the frame
        for (x, y) in [(k + 12, 9), (k + 12, SIZE - 9), (9, k + 12), (SIZE - 9, k + 12)]:
            ellipse(img, x, y, 3, 3, gold)
    return img


def painting_geometric(seed):
    rng = np.random.default_rng(seed)
    img = canvas((0.95, 0.93, 0.85))
    for _ in range(14):
        col = PALETTE[rng.integers(len(PALETTE))]
        x, y = rng.uniform(30, SIZE - 30, 2)
        r = rng.uniform(10, 50)
        k = rng.integers(3)
        if k == 0:
            ellipse(img, x, y, r, r, col)
            ellipse(img, x, y, r * 0.5, r * 0.5, PALETTE[rng.integers(len(PALETTE))])
        elif k == 1:
            a = rng.uniform(0, np.pi)
            n = int(rng.integers(3, 6))
            angles = a + 2 * np.pi * np.arange(n) / n
            polygon(img, list(zip(x + r * np.cos(angles), y + r * np.sin(angles))), col)
        else:
            rect(img, x - r, y - r / 3, x + r, y + r / 3, col)
    for _ in range(10):
        x0, y0, x1, y1 = rng.uniform(26, SIZE - 26, 4)
        line(img, x0, y0, x1, y1, rng.uniform(1.5, 4), (0.05, 0.05, 0.05))
    return painting_frame(img)


def painting_landscape(seed):
    rng = np.random.default_rng(seed)
    img = canvas((0.55, 0.75, 0.92))
    for i, c in enumerate([(0.60, 0.80, 0.95), (0.70, 0.85, 0.97), (0.85, 0.90, 0.95)]):
        rect(img, 0, 60 + 20 * i, SIZE, 80 + 20 * i, c)   # stepped sky bands
    ellipse(img, 190, 60, 16, 16, (0.98, 0.85, 0.20))
    for _ in range(5):   # clouds
        x, y = rng.uniform(30, 220), rng.uniform(35, 80)
        for k in range(3):
            ellipse(img, x + 10 * k, y + rng.uniform(-4, 4), 10, 7, (0.98, 0.98, 0.98))
    for i, col in enumerate([(0.45, 0.45, 0.55), (0.30, 0.45, 0.30)]):   # mountain ranges
        pts = [(0, SIZE)]
        xs = np.linspace(0, SIZE, 9)
        for x in xs:
            pts.append((x, rng.uniform(90, 140) + 25 * i))
        pts.append((SIZE, SIZE))
        polygon(img, pts, col)
    rect(img, 0, 170, SIZE, SIZE, (0.35, 0.60, 0.25))
    for _ in range(18):   # trees
        x, y = rng.uniform(25, SIZE - 25), rng.uniform(150, 230)
        s = rng.uniform(6, 14)
        rect(img, x - 1.5, y, x + 1.5, y + s * 0.8, (0.35, 0.22, 0.10))
        polygon(img, [(x - s, y + 2), (x, y - 2.2 * s), (x + s, y + 2)], (0.08, 0.35, 0.12))
    for _ in range(4):   # houses
        x, y = rng.uniform(30, SIZE - 60), rng.uniform(175, 215)
        w = rng.uniform(18, 30)
        rect(img, x, y, x + w, y + 16, PALETTE[rng.choice([8, 2, 12])])
        polygon(img, [(x - 3, y), (x + w / 2, y - 12), (x + w + 3, y)], (0.65, 0.15, 0.10))
        rect(img, x + 4, y + 5, x + 8, y + 10, (0.15, 0.15, 0.25))
        rect(img, x + w - 8, y + 5, x + w - 4, y + 10, (0.15, 0.15, 0.25))
    return painting_frame(img)


def painting_stripes(seed):
    """Op-art: bands of different stripe widths, a chequered strip and dots."""
    rng = np.random.default_rng(seed)
    img = canvas((0.95, 0.95, 0.95))
    y = 22
    while y < SIZE - 22:
        h = int(rng.integers(14, 34))
        col = PALETTE[rng.integers(len(PALETTE))]
        period = int(rng.integers(6, 24))
        kind = rng.integers(3)
        for x in range(22, SIZE - 22, period):
            if kind == 0:
                rect(img, x, y, x + period // 2, y + h, col)
            elif kind == 1:
                rect(img, x, y + (h // 2 if (x // period) % 2 else 0), x + period // 2,
                     y + (h if (x // period) % 2 else h // 2), col)
            else:
                ellipse(img, x + period / 2, y + h / 2, period / 3, h / 3, col)
        y += h + 3
    return painting_frame(img)


def poster_text(seed):
    """An information poster: title band, picture, columns of text, a logo strip."""
    rng = np.random.default_rng(seed)
    img = canvas((0.98, 0.97, 0.93))
    rect(img, 0, 0, SIZE, 48, (0.10, 0.25, 0.55))
    GLYPHS.text(img, 12, 10, SIZE - 12, 5, (0.98, 0.90, 0.20), rng, max_words=2)
    # Picture: a small scene of blocks.
    rect(img, 12, 58, 140, 150, (0.20, 0.20, 0.22))
    for _ in range(18):
        w, h = rng.uniform(8, 40, 2)
        x, y = rng.uniform(12, 140 - w), rng.uniform(58, 150 - h)
        rect(img, x, y, x + w, y + h, PALETTE[rng.integers(len(PALETTE))])
    for x0, x1, y0, y1 in [(150, 246, 60, 150), (12, 124, 162, 244), (134, 246, 162, 244)]:
        y = y0
        while y + 6 < y1:
            GLYPHS.text(img, x0, y, x1 - int(rng.integers(0, 30)), 1, (0.10, 0.10, 0.12), rng)
            y += 9 if rng.random() < 0.85 else 16
    frame(img, 0, 0, SIZE, SIZE, 3, (0.10, 0.25, 0.55))
    return img


def noticeboard(seed):
    """Cork board with pinned notes, photos and pins."""
    rng = np.random.default_rng(seed)
    cork = np.array([0.70, 0.52, 0.32])
    img = canvas(cork)
    for _ in range(500):   # cork granules (sparse dots, still compressible)
        x, y = rng.uniform(0, SIZE, 2)
        ellipse(img, x, y, 1.2, 1.2, cork * rng.choice([0.75, 1.15]))
    for _ in range(13):
        w, h = rng.uniform(40, 90), rng.uniform(30, 80)
        x, y = rng.uniform(-10, SIZE - w + 10), rng.uniform(-10, SIZE - h + 10)
        if rng.random() < 0.3:   # photo
            rect(img, x, y, x + w, y + h, (0.97, 0.97, 0.97))
            rect(img, x + 4, y + 4, x + w - 4, y + h - 12, PALETTE[rng.integers(len(PALETTE))])
            ellipse(img, x + w * 0.6, y + h * 0.4, w * 0.15, h * 0.15,
                    PALETTE[rng.integers(len(PALETTE))])
            polygon(img, [(x + 4, y + h - 12), (x + w * 0.35, y + h * 0.35),
                          (x + w * 0.6, y + h - 12)], PALETTE[rng.integers(len(PALETTE))])
        else:
            papers = [(0.98, 0.95, 0.55), (0.98, 0.98, 0.97), (0.65, 0.85, 0.95),
                      (0.98, 0.70, 0.75)]
            paper = papers[rng.integers(4)]
            rect(img, x, y, x + w, y + h, paper)
            yy = y + 6
            while yy + 6 < y + h:
                GLYPHS.text(img, x + 4, yy, x + w - 4, 1, (0.1, 0.1, 0.3), rng)
                yy += 8
        frame(img, x, y, x + w, y + h, 1, cork * 0.5)
        ellipse(img, x + w / 2, y + 4, 3.5, 3.5, PALETTE[rng.choice([0, 5, 3, 2])])
    frame(img, 0, 0, SIZE, SIZE, 8, (0.55, 0.40, 0.25))
    return img


def display_tiles(seed):
    """A display stand front: a 4x4 grid of different small patterns (multi-scale)."""
    rng = np.random.default_rng(seed)
    img = canvas((0.20, 0.20, 0.22))
    n = 4
    s = SIZE / n
    for i in range(n):
        for j in range(n):
            x0, y0 = j * s + 3, i * s + 3
            x1, y1 = x0 + s - 6, y0 + s - 6
            c1, c2 = PALETTE[rng.choice(len(PALETTE), 2, replace=False)]
            rect(img, x0, y0, x1, y1, c1)
            kind = (i * n + j + int(rng.integers(3))) % 5
            p = int(rng.integers(5, 14))
            for a in range(int(x0), int(x1), p):
                for b in range(int(y0), int(y1), p):
                    k = (a - int(x0)) // p + (b - int(y0)) // p
                    if kind == 0 and k % 2:
                        rect(img, a, b, min(a + p, x1), min(b + p, y1), c2)
                    elif kind == 1 and ((a - int(x0)) // p) % 2:
                        rect(img, a, b, min(a + p // 2, x1), min(b + p, y1), c2)
                    elif kind == 2:
                        ellipse(img, a + p / 2, b + p / 2, p / 3.2, p / 3.2, c2)
                    elif kind == 3 and rng.random() < 0.5:
                        rect(img, a, b, min(a + p - 1, x1), min(b + p - 1, y1), c2)
            if kind == 4:
                GLYPHS.word(img, x0 + 6, y0 + 8, 3, 4, c2, rng)
                GLYPHS.text(img, x0 + 4, y0 + 36, x1 - 4, 1, c2, rng)
                GLYPHS.text(img, x0 + 4, y0 + 44, x1 - 4, 1, c2, rng)
    return img


TEXTURES = {
    "crate_wood_a": lambda: crate_wood(101, (0.78, 0.58, 0.35), (0.10, 0.08, 0.06)),
    "crate_wood_b": lambda: crate_wood(102, (0.62, 0.66, 0.45), (0.70, 0.08, 0.06)),
    "cardboard": lambda: cardboard(103),
    "shelf_books": lambda: shelf_books(104),
    "shelf_bins": lambda: shelf_bins(105),
    "poster_blocks": lambda: poster_blocks(106),
    "poster_blobs": lambda: poster_blobs(107),
    "poster_text": lambda: poster_text(108),
    "painting_geometric": lambda: painting_geometric(109),
    "painting_landscape": lambda: painting_landscape(110),
    "painting_stripes": lambda: painting_stripes(111),
    "noticeboard": lambda: noticeboard(112),
    "display_tiles": lambda: display_tiles(113),
}


# (file suffix, np.rot90 turns): upright on -y, +y, -x and +x faces respectively.
ORIENTATIONS = [("", 0), ("_180", 2), ("_cw", -1), ("_ccw", 1)]


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    total = 0
    for name, make in TEXTURES.items():
        img = np.clip(make(), 0.0, 1.0)
        img8 = np.round(img * 255).astype(np.uint8)
        sizes = []
        for suffix, turns in ORIENTATIONS:
            path = os.path.join(OUT_DIR, name + suffix + ".png")
            # No 'Software' tag: the bytes then depend only on the pixels (and zlib).
            mpimg.imsave(path, np.ascontiguousarray(np.rot90(img8, turns)), format="png",
                         metadata={"Software": None})
            sizes.append(os.path.getsize(path))
        total += sum(sizes)
        print(f"{name:20s} {sum(sizes) / 1024:6.1f} KiB in {len(sizes)} orientations")
    print(f"total {total / 1024:.1f} KiB in {os.path.normpath(OUT_DIR)}")
    if total > 2 * 1024 * 1024:
        print("make_textures: PNGs exceed 2 MB", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

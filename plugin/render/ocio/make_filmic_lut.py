#!/usr/bin/env python3
"""Writes the Filmic view's 3D LUT of vfield's OpenColorIO config (config.ocio).

The view rolls highlights off towards white instead of clipping them:
  1. the brightest channel m = max(R, G, B) of scene-linear Rec.709 light goes
     through a film's tone curve, an S in stops about mid grey: mid grey
     (0.18) shows as the Standard view shows it, with CONTRAST display units a
     stop there (the Standard view has 0.15), a toe that rolls shadows off
     towards black and a shoulder that rolls highlights off towards white,
     which scene-linear WHITE all but reaches;
  2. the colour is scaled by curve(m) / m, so its ratios, hue and saturation
     are kept and no channel passes 1;
  3. the brighter it shows past TOWARDS_WHITE_FROM, the more it is mixed with
     the neutral of the brightest channel's value, in Oklab (Ottosson 2020),
     whose hue angle a straight mix keeps: a sunlit heap goes to white, as
     film does, without turning another hue on the way (a mix in RGB turns
     blue purple);
  4. the result is sRGB-encoded (IEC 61966-2-1) for the display.

The LUT holds the display's encoded values, indexed by the config's shaper, a
LogCameraTransform per channel: linear up to SHAPER_BREAK, where it meets a
log2 curve with the same slope, which reaches 1 at WHITE; the LUT's points are
then evenly spaced in stops, in which the curve is smooth.

Usage: make_filmic_lut.py OUT.cube
"""
import math
import os
import sys

MID_GREY = 0.18  # scene-linear; shown as 0.46, as the Standard view shows it
MID_GREY_SHOWN = 0.4613561  # sRGB-encoded 0.18
CONTRAST = 0.3  # sRGB-encoded display units a stop at mid grey
SHOULDER_SHARPNESS = 3.0  # the higher, the longer highlights keep their contrast
TOE_SHARPNESS = 2.0
TOWARDS_WHITE_FROM = 0.5  # display-linear: shown brighter, colours also go towards white
WHITE = 16.0  # scene-linear: the top of the LUT's range
SIZE = 33  # LUT points per axis

# The shaper x = LOG_SLOPE * log2(v) + LOG_OFFSET above SHAPER_BREAK, and
# LINEAR_SLOPE * v below it: continuous in value and slope, 0 at 0, 1 at WHITE.
SHAPER_BREAK = 2.0 ** -7
LOG_SLOPE = 1.0 / (math.log2(WHITE / SHAPER_BREAK) + 1.0 / math.log(2.0))
LOG_OFFSET = 1.0 - LOG_SLOPE * math.log2(WHITE)
LINEAR_SLOPE = LOG_SLOPE / (SHAPER_BREAK * math.log(2.0))


def sigmoid(d, sharpness):
    """Slope 1 at 0, rising to 1: d / (1 + d^k)^(1/k) for d >= 0."""
    return d / (1.0 + d ** sharpness) ** (1.0 / sharpness)


def tone(m):
    """The brightest channel's curve, scene-linear to display-linear.

    In stops s from mid grey, the display's sRGB-encoded value rises from
    MID_GREY_SHOWN with slope CONTRAST, towards 1 above and 0 below.
    """
    if m <= 0.0:
        return 0.0
    s = math.log2(m / MID_GREY)
    if s >= 0.0:
        shown = MID_GREY_SHOWN + (1.0 - MID_GREY_SHOWN) * sigmoid(CONTRAST * s / (1.0 - MID_GREY_SHOWN), SHOULDER_SHARPNESS)
    else:
        shown = MID_GREY_SHOWN * (1.0 - sigmoid(-CONTRAST * s / MID_GREY_SHOWN, TOE_SHARPNESS))
    return srgb_decode(shown)


def towards_white(toned):
    """How much of the neutral a colour whose brightest channel shows `toned` takes."""
    if toned <= TOWARDS_WHITE_FROM:
        return 0.0
    t = (toned - TOWARDS_WHITE_FROM) / (1.0 - TOWARDS_WHITE_FROM)
    return t * t


def to_oklab(rgb):
    r, g, b = rgb
    l = 0.4122214708 * r + 0.5363325363 * g + 0.0514459929 * b
    m = 0.2119034982 * r + 0.6806995451 * g + 0.1073969566 * b
    s = 0.0883024619 * r + 0.2817188376 * g + 0.6299787005 * b
    l, m, s = (math.copysign(abs(x) ** (1.0 / 3.0), x) for x in (l, m, s))
    return (0.2104542553 * l + 0.7936177850 * m - 0.0040720468 * s,
            1.9779984951 * l - 2.4285922050 * m + 0.4505937099 * s,
            0.0259040371 * l + 0.7827717662 * m - 0.8086757660 * s)


def from_oklab(lab):
    L, a, b = lab
    l = (L + 0.3963377774 * a + 0.2158037573 * b) ** 3
    m = (L - 0.1055613458 * a - 0.0638541728 * b) ** 3
    s = (L - 0.0894841775 * a - 1.2914855480 * b) ** 3
    return (4.0767416621 * l - 3.3077115913 * m + 0.2309699292 * s,
            -1.2684380046 * l + 2.6097574011 * m - 0.3413193965 * s,
            -0.0041960863 * l - 0.7034186147 * m + 1.7076147010 * s)


def srgb_encode(v):
    v = min(max(v, 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1.0 / 2.4) - 0.055


def srgb_decode(e):
    return e / 12.92 if e <= 0.04045 else ((e + 0.055) / 1.055) ** 2.4


def unshaped(x):
    """The scene-linear value the shaper maps to x."""
    if x <= LINEAR_SLOPE * SHAPER_BREAK:
        return x / LINEAR_SLOPE
    return 2.0 ** ((x - LOG_OFFSET) / LOG_SLOPE)


def view(rgb):
    m = max(rgb)
    if m <= 0.0:
        return (0.0, 0.0, 0.0)
    toned = tone(m)
    w = towards_white(toned)
    L, a, b = to_oklab([max(c, 0.0) * toned / m for c in rgb])
    white = to_oklab((toned, toned, toned))[0]
    return tuple(srgb_encode(c) for c in from_oklab((L + w * (white - L), (1.0 - w) * a, (1.0 - w) * b)))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_filmic_lut.py OUT.cube")
    lines = ['TITLE "vfield Filmic: scene-linear Rec.709 to sRGB, highlights rolled off to white"',
             f"# Made by make_filmic_lut.py: contrast {CONTRAST} a stop at mid grey; the config's shaper has",
             f"# log_side_slope {LOG_SLOPE:.10f}, log_side_offset {LOG_OFFSET:.10f}, lin_side_break {SHAPER_BREAK}.",
             f"LUT_3D_SIZE {SIZE}"]
    level = [unshaped(i / (SIZE - 1)) for i in range(SIZE)]
    for b in level:  # .cube: red changes fastest
        for g in level:
            for r in level:
                lines.append("%.7f %.7f %.7f" % view((r, g, b)))
    temporary = sys.argv[1] + ".tmp"
    with open(temporary, "w") as out:
        out.write("\n".join(lines) + "\n")
    os.replace(temporary, sys.argv[1])


if __name__ == "__main__":
    main()

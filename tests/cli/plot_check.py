"""Independent checks of `arco plot`'s folder (plot_cli_test.sh): Python's xml.etree, numpy
and Debian's ffmpeg/ffprobe CLI only.

  plot_check.py PLOT_DIR RESULT_DIR METHOD WIDTH HEIGHT EXPECT_ERRORS(0/1)

Each figure has NAME.svg and NAME.png; the PNG decodes (ffmpeg) at WIDTH x HEIGHT and is
not blank; the SVG parses as XML. pitch.svg has one note mark per row of the method's
fingering.csv with its name (data-name and a text element), placed at its onset (left
edge) and MIDI note (vertical centre) within a pixel of the plot area's axes;
fingerboard.svg has one mark per pressed note at its distance from the nut within a pixel.
"""
import csv
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np

plot_dir, result, method, width, height, expect_errors = sys.argv[1:7]
width, height = int(width), int(height)
SVG = "{http://www.w3.org/2000/svg}"
errors = []

names = ["pitch", "fingerboard"] + (["errors"] if expect_errors == "1" else [])
present = sorted(os.listdir(plot_dir))
expected = sorted([n + ".svg" for n in names] + [n + ".png" for n in names])
if present != expected:
    errors.append(f"files {present}, expected {expected}")

for n in names:
    png = os.path.join(plot_dir, n + ".png")
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", png, "-f", "rawvideo", "-pix_fmt",
                          "rgb24", "-"], capture_output=True).stdout
    if len(raw) != width * height * 3:
        errors.append(f"{png}: {len(raw)} bytes decoded, expected {width}x{height} RGB")
        continue
    img = np.frombuffer(raw, np.uint8).reshape(height, width, 3)
    ink = np.mean(np.any(img < 200, axis=2))
    colours = len(np.unique(img.reshape(-1, 3), axis=0))
    if ink < 0.01 or colours < 20:
        errors.append(f"{png}: looks blank ({ink:.3%} ink, {colours} colours)")

def area(root):
    a = [r for r in root.iter(SVG + "rect") if r.get("class") == "plot-area"]
    if len(a) != 1:
        raise SystemExit(f"{len(a)} plot areas")
    a = a[0]
    x, y, w, h = (float(a.get(k)) for k in ("x", "y", "width", "height"))
    xmin, xmax, ymin, ymax = (float(a.get("data-" + k)) for k in ("x-min", "x-max", "y-min", "y-max"))
    to_x = lambda v: x + (v - xmin) / (xmax - xmin) * w
    to_y = lambda v: y + h - (v - ymin) / (ymax - ymin) * h
    return to_x, to_y

rows = list(csv.DictReader(open(os.path.join(result, method, "fingering.csv"))))
pitch = ET.parse(os.path.join(plot_dir, "pitch.svg")).getroot()
to_x, to_y = area(pitch)
marks = [r for r in pitch.iter(SVG + "rect") if r.get("class") == "note"]
texts = [t.text or "" for t in pitch.iter(SVG + "text")]
if len(marks) != len(rows):
    errors.append(f"pitch.svg: {len(marks)} note marks, fingering.csv has {len(rows)} notes")
for m, r in zip(marks, rows):
    if m.get("data-name") != r["note_name"]:
        errors.append(f"pitch.svg: mark {m.get('data-name')} for note {r['note_name']}")
    if not any(t.startswith(r["note_name"] + " ") for t in texts):
        errors.append(f"pitch.svg: no label for {r['note_name']}")
    x = float(m.get("x"))
    yc = float(m.get("y")) + float(m.get("height")) / 2
    if abs(x - to_x(float(r["onset_s"]))) > 1 or abs(yc - to_y(int(r["midi_note"]))) > 1:
        errors.append(f"pitch.svg: note {r['note']} at ({x}, {yc}), expected "
                      f"({to_x(float(r['onset_s'])):.2f}, {to_y(int(r['midi_note'])):.2f})")
    right = x + float(m.get("width"))
    if abs(right - to_x(float(r["onset_s"]) + float(r["duration_s"]))) > 1:
        errors.append(f"pitch.svg: note {r['note']} ends at {right}")

board = ET.parse(os.path.join(plot_dir, "fingerboard.svg")).getroot()
to_x, to_y = area(board)
circles = [c for c in board.iter(SVG + "circle") if c.get("class") == "note"]
pressed = [r for r in rows if r["state"] == "pressed"]
placed = [c for c in circles if c.get("data-state") == "pressed"]
if len(placed) != len(pressed) or not pressed:
    errors.append(f"fingerboard.svg: {len(placed)} pressed marks, {len(pressed)} pressed notes")
for c, r in zip(placed, pressed):
    cx, cy = float(c.get("cx")), float(c.get("cy"))
    if c.get("data-name") != r["note_name"] or abs(cx - to_x(float(r["from_nut_mm"]))) > 1 or \
            abs(cy - to_y(int(r["string"]))) > 1:
        errors.append(f"fingerboard.svg: {c.get('data-name')} at ({cx}, {cy}), note "
                      f"{r['note_name']} at {r['from_nut_mm']} mm on string {r['string']}")

if errors:
    print("\n".join(errors))
    sys.exit(1)
print(f"ok: {len(names)} figures, {len(marks)} notes, {len(placed)} on the fingerboard")

#!/usr/bin/python3
"""Independent readers of `arco export`'s files, for export_cli_test.sh.

Each reader parses its format from the format's public description with only numpy and
struct (no arco code), and compares what it reads with the result folder's points3d.npy
and result.json. Prints one line per check; exit 1 on the first failure.

  export_check.py FORMAT FILE RESULT_DIR METHOD
"""
import csv
import json
import math
import struct
import sys

import numpy as np

TOL_MM = 1e-3


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def expect(cond, msg):
    if not cond:
        fail(msg)


def load_result(result_dir, method):
    r = json.load(open(result_dir + "/result.json"))
    stage = r["stages"][method]
    names = stage.get("keypoint_names", r["keypoint_names"])
    pts = np.load(result_dir + "/" + stage.get("dir", method) + "/" + stage["files"]["points3d"])
    return r, names, pts


def compare(read, pts, what):
    """read, pts: (F, P, 3); NaN where missing in both."""
    expect(read.shape == pts.shape, f"{what}: shape {read.shape} != {pts.shape}")
    gaps = np.isnan(pts).any(axis=2)
    expect((np.isnan(read).any(axis=2) == gaps).all(), f"{what}: gaps differ from points3d.npy")
    err = np.abs(read[~gaps] - pts[~gaps]).max() if (~gaps).any() else 0.0
    expect(err <= TOL_MM, f"{what}: max |difference| {err} mm > {TOL_MM}")
    print(f"{what}: {read.shape[0]} frames, {read.shape[1]} points, {gaps.sum()} gaps, "
          f"max difference {err:.2e} mm")


def check_csv(path, result, names, pts):
    rows = list(csv.reader(open(path)))
    expect(rows[0] == ["frame", "time_s", "keypoint", "x_mm", "y_mm", "z_mm", "present",
                       "reprojection_px", "views"], f"csv header {rows[0]}")
    # The triangulation's evidence, by name.
    tri_names = result["keypoint_names"]
    rms = np.load(result_dir_of[0] + "/triangulation/reprojection_rms_px.npy")
    inliers = np.load(result_dir_of[0] + "/triangulation/inlier_count.npy")
    quality_checked = 0
    F, P, _ = pts.shape
    expect(len(rows) == 1 + F * P, f"csv rows {len(rows) - 1} != {F * P}")
    read = np.full((F, P, 3), np.nan)
    first = result["frames"]["first"]
    fps = result["fps"]
    for i, row in enumerate(rows[1:]):
        f, p = divmod(i, P)
        expect(int(row[0]) == first + f and row[2] == names[p], f"csv row {i + 2}: {row[:3]}")
        expect(abs(float(row[1]) - f / fps) < 1e-5, f"csv row {i + 2}: time_s {row[1]}")
        name = names[p]
        expect(len(row) == 9, f"csv row {i + 2}: {len(row)} fields")
        t = tri_names.index(name) if name in tri_names else -1
        if t >= 0 and np.isfinite(rms[f, t]):
            expect(abs(float(row[7]) - rms[f, t]) <= 5e-4 and int(row[8]) == inliers[f, t],
                   f"csv row {i + 2}: reprojection_px/views {row[7:]} != {rms[f, t]}, "
                   f"{inliers[f, t]}")
            quality_checked += 1
        else:
            expect(row[7:] == ["", ""], f"csv row {i + 2}: quality {row[7:]} without one")
        if row[6] == "1":
            read[f, p] = [float(v) for v in row[3:6]]
        else:
            expect(row[3:6] == ["", "", ""], f"csv row {i + 2}: a gap with values")
    expect(quality_checked > 0, "csv: no reprojection_px values")
    compare(read, pts, "csv")
    print(f"csv: {quality_checked} reprojection_px/views values as in triangulation/")


def check_trc(path, result, names, pts):
    lines = open(path).read().split("\n")
    expect(lines[0].startswith("PathFileType\t4\t(X/Y/Z)\t"), "trc line 1")
    keys = lines[1].split("\t")
    vals = dict(zip(keys, lines[2].split("\t")))
    F, P, _ = pts.shape
    expect(abs(float(vals["DataRate"]) - result["fps"]) < 1e-9, "trc DataRate")
    expect(abs(float(vals["CameraRate"]) - result["fps"]) < 1e-9, "trc CameraRate")
    expect(int(vals["NumFrames"]) == F and int(vals["NumMarkers"]) == P, "trc counts")
    expect(vals["Units"] == "mm", "trc units")
    header = lines[3].split("\t")
    expect(header[:2] == ["Frame#", "Time"], "trc line 4")
    markers = [h for h in header[2:] if h]
    expect(markers == names, "trc marker names")
    expect(header[2::3][:P] == names, "trc marker columns")
    xyz = lines[4].split("\t")
    expect(xyz[2:5] == ["X1", "Y1", "Z1"] and len(xyz) == 2 + 3 * P, "trc line 5")
    expect(lines[5] == "", "trc blank line 6")
    read = np.full((F, P, 3), np.nan)
    for f in range(F):
        cells = lines[6 + f].split("\t")
        expect(len(cells) == 2 + 3 * P, f"trc frame {f + 1}: {len(cells)} fields")
        expect(int(cells[0]) == f + 1 and abs(float(cells[1]) - f / result["fps"]) < 1e-5,
               f"trc frame {f + 1} number/time")
        v = np.array([float(c) if c else np.nan for c in cells[2:]]).reshape(P, 3)
        read[f] = v
    compare(read, pts, "trc")


def c3d_params(buf, start_block):
    """Groups and parameters of a C3D parameter section -> {GROUP: {NAME: value}}."""
    pos = 512 * (start_block - 1)
    expect(buf[pos + 1] == 0x50, "c3d parameter key")
    expect(buf[pos + 3] == 84, "c3d processor type (Intel)")
    pos += 4
    groups, params = {}, []
    while True:
        nchars = struct.unpack_from("<b", buf, pos)[0]
        gid = struct.unpack_from("<b", buf, pos + 1)[0]
        if nchars == 0:
            break
        name = buf[pos + 2 : pos + 2 + abs(nchars)].decode()
        opos = pos + 2 + abs(nchars)
        offset = struct.unpack_from("<h", buf, opos)[0]
        if gid < 0:
            groups[-gid] = name
        else:
            p = opos + 2
            dtype = struct.unpack_from("<b", buf, p)[0]
            ndims = buf[p + 1]
            dims = list(buf[p + 2 : p + 2 + ndims])
            p += 2 + ndims
            count = int(np.prod(dims)) if dims else 1
            size = abs(dtype)
            raw = buf[p : p + count * size]
            if dtype == -1:
                if len(dims) == 2:
                    value = [raw[i * dims[0] : (i + 1) * dims[0]].decode().rstrip()
                             for i in range(dims[1])]
                else:
                    value = raw.decode().rstrip()
            elif dtype == 2:
                value = struct.unpack(f"<{count}h", raw)
            elif dtype == 4:
                value = struct.unpack(f"<{count}f", raw)
            else:
                value = raw
            if not dims and dtype != -1:
                value = value[0]
            params.append((gid, name, value))
        if offset == 0:
            break
        pos = opos + offset
    out = {}
    for gid, name, value in params:
        out.setdefault(groups[gid], {})[name] = value
    return out


def check_c3d(path, result, names, pts):
    buf = open(path, "rb").read()
    expect(len(buf) % 512 == 0, "c3d size is whole blocks")
    param_block, key = buf[0], buf[1]
    expect(key == 0x50, "c3d header key")
    npoints, nanalog, first, last, gap = struct.unpack_from("<5H", buf, 2)
    scale = struct.unpack_from("<f", buf, 12)[0]
    data_start = struct.unpack_from("<H", buf, 16)[0]
    rate = struct.unpack_from("<f", buf, 20)[0]
    F, P, _ = pts.shape
    expect(npoints == P and nanalog == 0, f"c3d header points {npoints}")
    expect(last - first + 1 == F, f"c3d header frames {first}..{last}")
    expect(scale < 0, "c3d scale < 0 (float data)")
    expect(abs(rate - result["fps"]) < 1e-4, f"c3d header rate {rate}")
    params = c3d_params(buf, param_block)
    pt = params["POINT"]
    expect(pt["USED"] == P, "POINT:USED")
    expect(pt["SCALE"] < 0, "POINT:SCALE < 0")
    expect(abs(pt["RATE"] - result["fps"]) < 1e-4, "POINT:RATE")
    expect(pt["UNITS"] == "mm", "POINT:UNITS")
    expect(pt["DATA_START"] == data_start, "POINT:DATA_START")
    expect(pt["FRAMES"] == F, "POINT:FRAMES")
    labels = []
    for suffix in [""] + [str(i) for i in range(2, 200)]:
        if "LABELS" + suffix not in pt:
            break
        labels += pt["LABELS" + suffix]
    expect(labels == names, "POINT:LABELS")
    data = np.frombuffer(buf, dtype="<f4", count=F * P * 4, offset=512 * (data_start - 1))
    data = data.reshape(F, P, 4).astype(np.float64)
    read = data[:, :, :3].copy()
    read[data[:, :, 3] < 0] = np.nan
    compare(read, pts, "c3d")


def check_glb(path, result, names, pts):
    buf = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<III", buf, 0)
    expect(magic == 0x46546C67 and version == 2 and length == len(buf), "glb header")
    jlen, jtype = struct.unpack_from("<II", buf, 12)
    expect(jtype == 0x4E4F534A, "glb JSON chunk")
    gltf = json.loads(buf[20 : 20 + jlen])
    blen, btype = struct.unpack_from("<II", buf, 20 + jlen)
    expect(btype == 0x004E4942, "glb BIN chunk")
    binary = buf[28 + jlen : 28 + jlen + blen]

    def accessor(i):
        a = gltf["accessors"][i]
        v = gltf["bufferViews"][a["bufferView"]]
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a["type"]]
        start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(binary, "<f4", a["count"] * n, start).reshape(a["count"], n)

    node_names = [n.get("name") for n in gltf["nodes"]]
    for name in names:
        expect(name in node_names, f"glb node {name}")
    for name in ["bow"] + [f"string{s}" for s in range(1, 5)]:
        expect(name in node_names, f"glb node {name}")
    F = pts.shape[0]
    anim = gltf["animations"][0]
    checked = 0
    for name in ["left_hand_index_tip", "left_hand_little_tip", "contact"]:
        node = node_names.index(name)
        p = names.index(name)
        ch = [c for c in anim["channels"]
              if c["target"]["node"] == node and c["target"]["path"] == "translation"]
        expect(len(ch) == 1, f"glb {name}: one translation channel")
        sampler = anim["samplers"][ch[0]["sampler"]]
        times = accessor(sampler["input"])[:, 0]
        values = accessor(sampler["output"])
        expect(len(times) == F and abs(times[-1] - (F - 1) / result["fps"]) < 1e-5,
               f"glb {name}: {len(times)} keyframes")
        for f in sorted({0, F // 3, F // 2, F - 1}):
            if np.isnan(pts[f, p]).any():
                continue
            err_mm = np.abs(values[f].astype(np.float64) * 1000 - pts[f, p]).max()
            expect(err_mm <= TOL_MM, f"glb {name} frame {f}: {err_mm} mm")
            checked += 1
    expect(checked >= 4, "glb: too few frames checked")
    print(f"glb: {len(gltf['nodes'])} nodes, {F} keyframes, {checked} translations within "
          f"{TOL_MM} mm")


def parse_bvh(path):
    tokens_lines = [l.split() for l in open(path).read().split("\n")]
    joints, stack, residual = [], [], {}
    i = 0
    while True:
        t = tokens_lines[i]
        i += 1
        if not t:
            continue
        if t[0] == "#":
            if len(t) > 1 and t[1] == "residual_mm":
                residual[t[2]] = (float(t[4]), float(t[6]))
            continue
        if t[0] in ("ROOT", "JOINT"):
            joints.append({"name": t[1], "parent": stack[-1] if stack else -1})
            stack.append(len(joints) - 1)
        elif t[0] == "End":
            stack.append(None)
        elif t[0] == "OFFSET" and stack[-1] is not None:
            joints[stack[-1]]["offset"] = np.array([float(v) for v in t[1:4]])
        elif t[0] == "CHANNELS":
            joints[stack[-1]]["channels"] = t[2 : 2 + int(t[1])]
        elif t[0] == "}":
            stack.pop()
        elif t[0] == "MOTION":
            break
    frames = int(tokens_lines[i][1])
    frame_time = float(tokens_lines[i + 1][2])
    motion = np.array([[float(v) for v in l] for l in tokens_lines[i + 2 : i + 2 + frames]])
    return joints, residual, frames, frame_time, motion


def axis_rotation(axis, deg):
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return {"X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def check_bvh(path, result, names, pts, method):
    joints, residual, frames, frame_time, motion = parse_bvh(path)
    F = pts.shape[0]
    expect(frames == F and motion.shape[0] == F, f"bvh frames {frames}")
    expect(abs(frame_time - 1 / result["fps"]) < 1e-7, f"bvh frame time {frame_time}")
    expect(motion.shape[1] == sum(len(j["channels"]) for j in joints), "bvh channel count")
    for side in ("left", "right"):
        for finger in ("index", "middle", "ring", "little"):
            for joint in ("mcp", "pip", "dip", "tip"):
                expect(any(j["name"] == f"{side}_hand_{finger}_{joint}" for j in joints),
                       f"bvh joint {side}_hand_{finger}_{joint}")
    worst = 0.0
    errors = {}  # per joint: |forward kinematics - points3d.npy| over the frames
    for f in range(F):
        col = 0
        world = []
        for j in joints:
            t, r = j["offset"].copy(), np.eye(3)
            for ch in j["channels"]:
                v = motion[f, col]
                col += 1
                if ch.endswith("position"):
                    t["XYZ".index(ch[0])] = v
                else:
                    r = r @ axis_rotation(ch[0], v)
            if j["parent"] < 0:
                world.append((r, t))
            else:
                pr, pp = world[j["parent"]]
                world.append((pr @ r, pp + pr @ t))
        for j, (_, p) in zip(joints, world):
            if j["name"] not in residual:
                continue
            target = pts[f, names.index(j["name"])]
            if np.isnan(target).any():
                continue
            err = np.linalg.norm(p - target)
            errors.setdefault(j["name"], []).append(err)
            expect(err <= residual[j["name"]][1] + 0.01,
                   f"bvh frame {f} {j['name']}: FK error {err:.4f} mm > reported max "
                   f"{residual[j['name']][1]:.4f}")
            worst = max(worst, err - residual[j["name"]][1])
    hand = [k for k in residual if k.startswith("left_hand_")]
    expect(len(hand) == 21, "bvh: 21 left hand joints with residuals")
    # The arco method's body and right hand are a fitted skeleton's (docs/export.md, "BVH"),
    # its left hand the fitted hand model's: the BVH reproduces every body and hand joint
    # within 1 mm (median over frames, by this script's own forward kinematics).
    if method == "arco":
        groups = {"body": [], "left hand": [], "right hand": []}
        for k, e in errors.items():
            if names.index(k) >= 133:
                continue  # the instrument and the bow
            g = "left hand" if k.startswith("left_hand_") else (
                "right hand" if k.startswith("right_hand_") else "body")
            groups[g] += e
            expect(np.median(e) <= 1.0, f"bvh {k}: median FK error {np.median(e):.4f} mm > 1 mm")
        expect(len(groups["body"]) >= 23 * (F - 1) and len(groups["right hand"]) == 21 * F,
               "bvh: every body and right hand joint checked")
        for g, e in groups.items():
            expect(np.median(e) <= 1.0, f"bvh {g}: median FK error {np.median(e):.4f} mm > 1 mm")
        print("bvh (arco): median FK error mm: " +
              ", ".join(f"{g} {np.median(e):.2e}" for g, e in groups.items()))
    print(f"bvh: {len(joints)} joints, {F} frames, FK within the reported residuals "
          f"(+{max(worst, 0):.2e} mm); left hand median residual "
          f"{np.median([residual[k][0] for k in hand]):.4f} mm")


result_dir_of = []


def main():
    fmt, path, result_dir, method = sys.argv[1:5]
    result_dir_of.append(result_dir)
    result, names, pts = load_result(result_dir, method)
    {"csv": check_csv, "trc": check_trc, "c3d": check_c3d, "gltf": check_glb,
     "bvh": check_bvh}[fmt](path, result, names, pts, *([method] if fmt == "bvh" else []))


if __name__ == "__main__":
    main()

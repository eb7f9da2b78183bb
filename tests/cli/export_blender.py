"""Blender's own importers read `arco export`'s BVH and glTF (the issue's consumer test).

Run: blender -b --factory-startup --python export_blender.py -- BVH GLB RESULT_DIR METHOD
Checks, for each file: the frame count, the joint/node count, and that left fingertips'
(and, in the BVH, instrument points') world positions at several frames are within 1 mm of points3d.npy (in the export's units:
mm for BVH, metres for glTF). Exits 1 on the first failure.
"""
import builtins
import json
import math
import sys

import bpy
import numpy as np
from mathutils import Vector

TOL_MM = 1.0


def fail(msg):
    print("FAIL: " + msg)
    sys.stdout.flush()
    sys.exit(1)


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def main():
    bvh, glb, result_dir, method = sys.argv[sys.argv.index("--") + 1 :][:4]
    result = json.load(open(result_dir + "/result.json"))
    stage = result["stages"][method]
    names = stage["keypoint_names"]
    pts = np.load(result_dir + "/" + stage.get("dir", method) + "/" + stage["files"]["points3d"])
    F = pts.shape[0]
    fps = result["fps"]
    frames = sorted({0, F // 3, F // 2, F - 1})
    tips = ["left_hand_index_tip", "left_hand_middle_tip", "left_hand_little_tip", "left_hand_thumb_tip"]

    # BVH. Blender 3.4's importer opens the file with mode 'rU', which Python 3.11 rejects.
    clear()
    real_open = builtins.open

    def open_without_u(file, mode="r", *args, **kwargs):
        return real_open(file, mode.replace("U", ""), *args, **kwargs)

    builtins.open = open_without_u
    try:
        bpy.ops.import_anim.bvh(filepath=bvh, global_scale=1.0, frame_start=1,
                                use_fps_scale=False, update_scene_fps=True,
                                update_scene_duration=True, rotate_mode="NATIVE",
                                axis_forward="Y", axis_up="Z")
    finally:
        builtins.open = real_open
    arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
    if len(arm) != 1:
        fail(f"bvh: {len(arm)} armatures")
    arm = arm[0]
    # 67 skeleton joints, the instrument root and its points, the bow root, frog and tip.
    instrument = ["scroll_top", "nut_l", "nut_r", "bridge_l", "bridge_r", "tail_gut", "end_pin"]
    instrument += [f"string{s}_{e}" for s in range(1, 5) for e in ("top", "bottom")]
    expected = 67 + 1 + sum(n in names for n in instrument) + 3
    bones = len(arm.data.bones)
    if bones != expected:
        fail(f"bvh: {bones} bones, expected {expected}")
    start, end = arm.animation_data.action.frame_range
    if int(round(end - start)) + 1 != F:
        fail(f"bvh: action frames {start}..{end}, expected {F}")
    worst = 0.0
    for f in frames:
        bpy.context.scene.frame_set(f + 1)
        for tip in tips + ["scroll_top", "string1_top", "string4_bottom"]:
            target = pts[f, names.index(tip)]
            if np.isnan(target).any():
                continue
            p = arm.matrix_world @ arm.pose.bones[tip].head
            err = (Vector(target.tolist()) - p).length
            worst = max(worst, err)
            if err > TOL_MM:
                fail(f"bvh frame {f}: {tip} at {tuple(p)}, points3d {tuple(target)}: {err:.3f} mm")
    print(f"blender bvh: {bones} bones, {F} frames, left fingertips and instrument points "
          f"within {worst:.4f} mm")

    # glTF. Blender 3.4's importer uses np.bool, which Debian's NumPy 1.24 no longer has.
    if "bool" not in np.__dict__:
        np.bool = bool
    # Blender turns glTF's +Y up into +Z up: (x, y, z) -> (x, -z, y).
    clear()
    bpy.context.scene.render.fps = int(round(fps))
    bpy.context.scene.render.fps_base = round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=glb)
    objects = {o.name: o for o in bpy.context.scene.objects}
    for name in names + ["bow", "string1", "string4"]:
        if name not in objects:
            fail(f"glb: no object {name}")
    obj = objects["left_hand_index_tip"]
    start, end = obj.animation_data.action.frame_range
    if int(round(end - start)) + 1 != F:
        fail(f"glb: action frames {start}..{end}, expected {F}")
    worst = 0.0
    for f in frames:
        bpy.context.scene.frame_set(int(round(start)) + f)
        bpy.context.view_layer.update()
        for tip in tips:
            target = pts[f, names.index(tip)]
            if np.isnan(target).any():
                continue
            p = objects[tip].matrix_world.translation
            gltf = Vector((p.x, p.z, -p.y)) * 1000.0
            err = (Vector(target.tolist()) - gltf).length
            worst = max(worst, err)
            if err > TOL_MM:
                fail(f"glb frame {f}: {tip} at {tuple(gltf)} mm, points3d {tuple(target)}: "
                     f"{err:.3f} mm")
    print(f"blender glb: {len(objects)} objects, {F} frames, left fingertips within {worst:.4f} mm")


main()

"""Imports exported motion into Blender and checks every joint's position against what the playground showed.

    blender -b --factory-startup -P tests/blender/check_import.py -- FILE EXPECTED.json [FILE EXPECTED.json ...]

FILE is a .glb (imported with bpy.ops.import_scene.gltf) or a .bvh (bpy.ops.import_anim.bvh, centimetres).
EXPECTED.json, written by the node side (tests/e2e/blender.test.mjs):
    {"fps": 30, "frames": [0, 2, ...], "joints": {"Hips": [[x, y, z], ...], ...}}
i.e. per joint (its bone's name in the file) its position at each listed frame index, in the playground's
frame (metres, y up, +z forward). For each frame the scene is set to the frame the importer put that motion
frame on and each pose bone's head (its joint) is read in world space, armature.matrix_world @ head, then
taken back from Blender's z-up frame (both importers turn y-up files to z-up: Blender (x, y, z) =
playground (x, -z, y)). Prints one "RESULT {json}" line per file (max error in metres, where, how much was
checked, and how many meshes the armature deforms) and exits 1 when any file's max error exceeds 1 mm, a joint
has no bone or a .glb's figure is not skinned to the armature; 2 on bad arguments.
"""
import builtins
import json
import math
import sys

import bpy

TOLERANCE_M = 0.001


def allow_blender_34_importers():
    """Blender 3.4's importers on Debian 12's Python 3.11 and numpy 1.24: the BVH importer opens files with mode
    'rU' (rejected since Python 3.11) and the glTF importer uses numpy.bool (removed in numpy 1.24)."""
    real_open = builtins.open

    def open_without_universal_newlines(file, mode='r', *args, **kwargs):
        if isinstance(mode, str) and 'U' in mode:
            mode = mode.replace('U', '')
        return real_open(file, mode, *args, **kwargs)

    builtins.open = open_without_universal_newlines
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool


def import_motion(path, fps):
    """Imports the file into an empty scene; returns the armature and a function from motion frame index to
    (scene frame, subframe)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    if path.lower().endswith('.bvh'):
        # Keys land on frame_start + i whatever the rate (use_fps_scale off); the scene takes the file's rate.
        bpy.ops.import_anim.bvh(
            filepath=path, global_scale=0.01, frame_start=1, use_fps_scale=False, update_scene_fps=True,
            update_scene_duration=True, rotate_mode='NATIVE', axis_forward='-Z', axis_up='Y')
        to_scene = lambda i: (1 + i, 0.0)
    else:
        # The glTF importer keys time t at frame t * scene.render.fps.
        scene.render.fps = max(1, round(fps))
        scene.render.fps_base = 1
        bpy.ops.import_scene.gltf(filepath=path)

        def to_scene(i):
            frame = i / fps * scene.render.fps
            whole = math.floor(frame + 1e-9)
            return whole, max(0.0, frame - whole)
    armatures = [o for o in scene.objects if o.type == 'ARMATURE']
    if len(armatures) != 1:
        raise RuntimeError(f'{path}: expected one armature after import, found {len(armatures)}')
    return armatures[0], to_scene


def skinned_meshes(armature):
    """How many meshes the armature deforms (an Armature modifier on it and vertex groups named after its
    bones): a glTF skin must arrive as a skinned figure, not as loose meshes beside an armature."""
    count = 0
    for o in bpy.context.scene.objects:
        if o.type != 'MESH':
            continue
        deformed = any(m.type == 'ARMATURE' and m.object == armature for m in o.modifiers)
        grouped = any(g.name in armature.data.bones for g in o.vertex_groups)
        count += deformed and grouped
    return count


def check(path, expected_path):
    with open(expected_path) as f:
        expected = json.load(f)
    armature, to_scene = import_motion(path, expected['fps'])
    bones = armature.pose.bones
    missing = [name for name in expected['joints'] if name not in bones]
    worst = {'error_m': 0.0, 'joint': None, 'frame': None}
    scene = bpy.context.scene
    for k, i in enumerate(expected['frames']):
        frame, subframe = to_scene(i)
        scene.frame_set(frame, subframe=subframe)
        world = armature.matrix_world
        for name, track in expected['joints'].items():
            if name in missing:
                continue
            head = world @ bones[name].head
            shown = (head.x, head.z, -head.y)  # back to y up, +z forward
            error = math.dist(shown, track[k])
            if error > worst['error_m']:
                worst = {'error_m': error, 'joint': name, 'frame': i}
    skinned = skinned_meshes(armature)
    result = {
        'file': path, 'max_error_m': worst['error_m'], 'worst_joint': worst['joint'], 'worst_frame': worst['frame'],
        'frames_checked': len(expected['frames']), 'joints_checked': len(expected['joints']) - len(missing),
        'missing_bones': missing, 'skinned_meshes': skinned,
        'ok': not missing and worst['error_m'] <= TOLERANCE_M and (skinned > 0 or not path.lower().endswith('.glb')),
    }
    print('RESULT ' + json.dumps(result), flush=True)
    return result['ok']


def main():
    args = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
    if len(args) < 2 or len(args) % 2:
        print('usage: blender -b --factory-startup -P check_import.py -- FILE EXPECTED.json [FILE EXPECTED.json ...]', file=sys.stderr)
        sys.exit(2)
    allow_blender_34_importers()
    ok = True
    for path, expected_path in zip(args[::2], args[1::2]):
        ok = check(path, expected_path) and ok
    sys.exit(0 if ok else 1)


main()

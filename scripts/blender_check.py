"""Imports a glTF/GLB written by `sylva export` into Blender and checks that Blender reads
what the file holds: every triangle, every material (double-sided, colour, texture), the
skeleton in the plant nodes' extras. Optionally renders the imported plant with Cycles.

Run by Blender in background mode (Debian's blender 3.4):

    blender -b --factory-startup --python-exit-code 1 --python scripts/blender_check.py -- \
        plant.glb [--render out.png --size 480x360 --samples 16] [--pose-frames F1,F2,... --every N]

A rigged file (`sylva export --rig [--animation]`) is checked too: one armature bone per
skin joint, one action per animation spanning its keys at the scene's 24 fps, and the
skinned mesh's first and last frame equal. With --pose-frames, report["rig"]["poses"]
holds, for every N-th vertex of each skinned mesh, its rest and its evaluated (deformed)
world position at each frame, in glTF's axes (Y up), for the caller to compare with
sylva's own pose (tests/app/blender_check_test.cpp).

Prints one line `BLENDER_CHECK {json}` (the report: counts from the file and from Blender,
the problems found) and exits 1 when there is a problem (tests/app/blender_check_test.cpp).
The expected counts come from the file's own JSON chunk, read here without Blender.
"""

import json
import math
import struct
import sys


def read_gltf_json(path):
    """The JSON of a .glb (its first chunk) or a .gltf file."""
    data = open(path, "rb").read()
    if data[:4] == b"glTF":
        length, kind = struct.unpack_from("<II", data, 12)
        if kind != 0x4E4F534A:  # "JSON"
            raise ValueError(f"{path}: the GLB's first chunk is not JSON")
        return json.loads(data[20:20 + length])
    return json.loads(data)


def expected_from_file(doc):
    """Per mesh: its triangle count (TRIANGLES primitives) and the materials its primitives use;
    and the number of nodes that draw each mesh (Blender makes one object per node)."""
    meshes = []
    for mesh in doc.get("meshes", []):
        triangles, materials = 0, []
        for primitive in mesh["primitives"]:
            if primitive.get("mode", 4) != 4:
                continue
            accessor = doc["accessors"][primitive["indices"]] if "indices" in primitive else \
                doc["accessors"][primitive["attributes"]["POSITION"]]
            triangles += accessor["count"] // 3
            if "material" in primitive:
                materials.append(doc["materials"][primitive["material"]]["name"])
        meshes.append({"name": mesh.get("name", ""), "triangles": triangles, "materials": sorted(set(materials))})
    plant_nodes = [n.get("name", "") for n in doc.get("nodes", [])
                   if isinstance(n.get("extras"), dict) and "sylva" in n["extras"]]
    return meshes, plant_nodes


def principled(material):
    """The Principled BSDF node of a Blender material (the glTF importer makes one)."""
    if not material.use_nodes:
        return None
    for node in material.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            return node
    return None


def uv_map_of(node, depth=0):
    """The UV layer a texture node reads: the uv_map of the UV Map node feeding its Vector
    input (through any nodes in between), "" when none does (the mesh's first layer)."""
    if node.type == "UVMAP":
        return node.uv_map
    if depth > 4:
        return ""
    for socket in node.inputs:
        if socket.is_linked:
            found = uv_map_of(socket.links[0].from_node, depth + 1)
            if found:
                return found
    return ""


def check(path, problems):
    import bpy

    doc = read_gltf_json(path)
    meshes, plant_nodes = expected_from_file(doc)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)

    report = {"file": path, "meshes": [], "materials": [], "plant_nodes": plant_nodes, "extras": []}
    # Blender names a second mesh of one name "NAME.001" and so on, in an order of its own:
    # the meshes of one name are compared as a multiset of (triangles, materials).
    import re
    imported, seen = {}, set()
    for o in bpy.context.scene.objects:
        if o.type != "MESH" or o.data.name in seen:
            continue  # instancing: several objects share one mesh
        seen.add(o.data.name)
        polygons = o.data.polygons
        imported.setdefault(re.sub(r"\.\d{3}$", "", o.data.name), []).append({
            "triangles": sum(len(p.vertices) - 2 for p in polygons),
            "materials": sorted({s.material.name for s in o.material_slots if s.material}),
            "uv_layers": [uv.name for uv in o.data.uv_layers]})
    wanted = {}
    for expected in meshes:
        if expected["triangles"] > 0:  # not a LINES-only mesh (the skeleton without --mesh)
            wanted.setdefault(expected["name"], []).append(expected)
    key = lambda m: (m["triangles"], m["materials"])
    for name, expected_list in wanted.items():
        got = sorted(imported.get(name, []), key=key)
        expected_list = sorted(expected_list, key=key)
        if not got:
            problems.append(f"mesh {name!r} was not imported")
            continue
        if len(got) != len(expected_list):
            problems.append(f"mesh {name!r}: {len(expected_list)} meshes in the file, {len(got)} in Blender")
        for expected, o in zip(expected_list, got):
            report["meshes"].append({"name": name, "triangles_file": expected["triangles"],
                                     "triangles_blender": o["triangles"], "materials": o["materials"],
                                     "uv_layers": o["uv_layers"]})
            if o["triangles"] != expected["triangles"]:
                problems.append(f"mesh {name!r}: {expected['triangles']} triangles in the file, "
                                f"{o['triangles']} in Blender")
            if o["materials"] != expected["materials"]:
                problems.append(f"mesh {name!r}: materials {expected['materials']} in the file, "
                                f"{o['materials']} in Blender")

    for m in doc.get("materials", []):
        b = bpy.data.materials.get(m["name"])
        if b is None:
            problems.append(f"material {m['name']!r} was not imported")
            continue
        pbr = m.get("pbrMetallicRoughness", {})
        node = principled(b)
        entry = {"name": m["name"], "double_sided": not b.use_backface_culling,
                 "blend_method": b.blend_method, "textured": False}
        if node is None:
            problems.append(f"material {m['name']!r} has no Principled BSDF")
        else:
            base = node.inputs["Base Color"]
            entry["textured"] = base.is_linked
            if "baseColorTexture" in pbr and not base.is_linked:
                problems.append(f"material {m['name']!r}: its baseColorTexture is not linked to Base Color")
            if "baseColorTexture" in pbr and base.is_linked:
                # Which UV layer the texture reads: the importer wires TEXCOORD_k (k > 0)
                # through a UV Map node naming layer k ("UVMap.001"); layer 0 needs none.
                texcoord = pbr["baseColorTexture"].get("texCoord", 0)
                entry["uv_map"] = uv_map_of(base.links[0].from_node)
                want = "UVMap" if texcoord == 0 else f"UVMap.{texcoord:03d}"
                if (entry["uv_map"] or "UVMap") != want:
                    problems.append(f"material {m['name']!r}: its baseColorTexture reads TEXCOORD_{texcoord} in the "
                                    f"file, UV map {entry['uv_map'] or 'UVMap'!r} in Blender")
            if "baseColorTexture" not in pbr:
                want = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
                got = list(base.default_value)[:3]
                entry["base_color"] = got
                if any(abs(a - b_) > 1e-5 for a, b_ in zip(want, got)):
                    problems.append(f"material {m['name']!r}: base colour {want} in the file, {got} in Blender")
        if bool(m.get("doubleSided", False)) != entry["double_sided"]:
            problems.append(f"material {m['name']!r}: doubleSided {m.get('doubleSided', False)} in the file, "
                            f"backface culling {b.use_backface_culling} in Blender")
        if m.get("alphaMode") == "MASK" and b.blend_method != "CLIP":
            problems.append(f"material {m['name']!r}: alphaMode MASK in the file, blend method {b.blend_method}")
        report["materials"].append(entry)

    # The skeleton in extras becomes a custom property `sylva` of the plant's object.
    for name in plant_nodes:
        o = bpy.data.objects.get(name)
        sylva = o.get("sylva") if o is not None else None
        if isinstance(sylva, str):  # a value Blender could not keep as a property group
            try:
                sylva = json.loads(sylva)
            except ValueError:
                sylva = None
        fmt = sylva.get("format") if hasattr(sylva, "get") else None
        report["extras"].append({"node": name, "format": fmt})
        if fmt != "sylva-skeleton":
            problems.append(f"node {name!r}: no sylva skeleton in its Blender custom properties")
    return report


def look_at(camera, target):
    from mathutils import Vector

    direction = Vector(target) - camera.location
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def render(out, width, height, samples):
    """Cycles on the CPU: the imported plant from the south-west, a sun, a sky colour."""
    import bpy
    from mathutils import Vector

    scene = bpy.context.scene
    points = [o.matrix_world @ Vector(c) for o in scene.objects if o.type == "MESH" for c in o.bound_box]
    lo = Vector((min(p.x for p in points), min(p.y for p in points), min(p.z for p in points)))
    hi = Vector((max(p.x for p in points), max(p.y for p in points), max(p.z for p in points)))
    centre = (lo + hi) / 2
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit = "HORIZONTAL"
    camera_data.angle = math.radians(40)
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    # Blender is Z-up (the importer turns glTF's Y-up into it): look from the -Y side, a little above.
    # Far enough that the box's height fits the vertical field and its width the horizontal.
    half_h = math.radians(40) / 2
    half_v = math.atan(math.tan(half_h) * height / width)
    extent = hi - lo
    across = max(extent.x, extent.y)
    distance = 1.08 * max(extent.z / 2 / math.tan(half_v), across / 2 / math.tan(half_h)) + across / 2
    camera.location = centre + Vector((0.35, -1.0, 0.15)).normalized() * distance
    look_at(camera, centre)
    scene.camera = camera
    sun_data = bpy.data.lights.new("sun", "SUN")
    sun_data.energy = 3.0
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(-30))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.7, 0.9, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.filepath = out
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    bpy.ops.render.render(write_still=True)


def gltf_axes(v):
    """A Blender (Z up) world position in glTF's axes (Y up): the importer's (x, -z, y) undone."""
    return [v[0], v[2], -v[1]]


def check_rig(doc, report, problems, pose_frames, every):
    """The skins and the wind clip: bones, actions, the loop, and the poses asked for."""
    import bpy

    skins = doc.get("skins", [])
    if not skins:
        return
    scene = bpy.context.scene
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    rig = {"skin_joints": [len(s["joints"]) for s in skins],
           "armatures": [{"name": o.name, "bones": len(o.data.bones)} for o in armatures],
           "actions": [], "poses": []}
    if sorted(rig["skin_joints"]) != sorted(a["bones"] for a in rig["armatures"]):
        problems.append(f"skins with {rig['skin_joints']} joints in the file, armatures with "
                        f"{[a['bones'] for a in rig['armatures']]} bones in Blender")
    fps = scene.render.fps / scene.render.fps_base
    for animation in doc.get("animations", []):
        end = max(doc["accessors"][s["input"]]["max"][0] for s in animation["samplers"])
        actions = [a for a in bpy.data.actions if a.name.startswith(animation.get("name", ""))]
        rig["actions"] += [{"name": a.name, "frame_range": list(a.frame_range)} for a in actions]
        if not any(abs(a.frame_range[0]) < 1e-6 and abs(a.frame_range[1] - end * fps) < 1e-3 for a in actions):
            problems.append(f"animation {animation.get('name')!r}: no action spans frames 0 to {end * fps:g}")
    skinned = [o for o in scene.objects if o.type == "MESH" and o.find_armature() is not None]
    if len(skinned) != len(skins):
        problems.append(f"{len(skins)} skins in the file, {len(skinned)} skinned meshes in Blender")

    def evaluated(o, frame):
        scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        e = o.evaluated_get(depsgraph)
        mesh = e.to_mesh()
        world = [gltf_axes(e.matrix_world @ v.co) for v in mesh.vertices]
        e.to_mesh_clear()
        return world

    if doc.get("animations"):
        last = round(max(a["frame_range"][1] for a in rig["actions"])) if rig["actions"] else 0
        for o in skinned:
            first, final = evaluated(o, 0), evaluated(o, last)
            size = max(max(abs(c) for c in p) for p in first) or 1
            gap = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(first, final))
            rig.setdefault("loop_gap", []).append(gap)
            if gap > 1e-5 * size:
                problems.append(f"mesh {o.name!r}: frame {last} differs from frame 0 by {gap:g}: the clip does not loop")
    for frame in pose_frames:
        for o in skinned:
            rest = [gltf_axes(v.co) for v in o.data.vertices]  # the file's POSITION, in mesh space
            posed = evaluated(o, frame)
            rig["poses"].append({"mesh": o.name, "frame": frame, "time_s": frame / fps,
                                 "rest": [c for p in rest[::every] for c in p],
                                 "posed": [c for p in posed[::every] for c in p]})
    report["rig"] = rig


def main(argv):
    import numpy as np

    if not hasattr(np, "bool"):
        np.bool = bool  # Debian's Blender 3.4 importer uses np.bool, gone in numpy 1.24
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if not args:
        print("usage: blender -b --python scripts/blender_check.py -- FILE.glb [--render OUT.png] "
              "[--size WxH] [--samples N]", file=sys.stderr)
        return 2
    path, out, size, samples, pose_frames, every = args[0], None, (480, 360), 16, [], 1
    rest = args[1:]
    while rest:
        flag = rest.pop(0)
        if flag == "--render":
            out = rest.pop(0)
        elif flag == "--size":
            w, h = rest.pop(0).split("x")
            size = (int(w), int(h))
        elif flag == "--samples":
            samples = int(rest.pop(0))
        elif flag == "--pose-frames":
            pose_frames = [int(f) for f in rest.pop(0).split(",")]
        elif flag == "--every":
            every = max(1, int(rest.pop(0)))
        else:
            print(f"blender_check.py: unknown flag {flag}", file=sys.stderr)
            return 2
    problems = []
    report = check(path, problems)
    check_rig(read_gltf_json(path), report, problems, pose_frames, every)
    report["problems"] = problems
    print("BLENDER_CHECK " + json.dumps(report), flush=True)
    if out:
        render(out, size[0], size[1], samples)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

"""The add-on's tests, the part that runs inside Blender: `blender -b --factory-startup -P
in_blender.py -- CASE OUT [ARGS]` builds a scene, exports and renders it, and writes what it saw
into the folder OUT (result.json, arrays as .npy) for test_blender.py to check."""
import json
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import build_scenes as bs  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:]
CASE, OUT = ARGS[0], ARGS[1]
result = {}


def render(path):
    """F12 into an EXR (linear, 32-bit float); returns the reports nothing: errors raise."""
    bpy.context.scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def export(path):
    return bpy.ops.export_scene.nimbus(filepath=path)


def reports_of(operator_call):
    """Runs an operator and returns (ok, message) of the RuntimeError Blender raises for an error
    report, or (True, "")."""
    try:
        operator_call()
        return True, ""
    except RuntimeError as e:
        return False, str(e)


def case_metaballs():
    """The sculpture's free form, and Blender's own field at random points, computed here from
    the elements with Blender's math (mathutils), and Blender's own tessellation's vertices."""
    scene = bs.empty_scene()
    bs.add_camera(scene)
    a, b = bs.sculpture(scene)
    export(os.path.join(OUT, "scene.json"))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rng = np.random.default_rng(7)
    points = rng.uniform([-1.6, -1.1, -1.1], [1.8, 1.3, 1.9], size=(100000, 3))
    field = np.zeros(len(points))
    for obj in (a, b):
        world = obj.evaluated_get(depsgraph).matrix_world
        for el in obj.data.elements:
            from mathutils import Matrix
            element = world @ Matrix.Translation(el.co) @ el.rotation.to_matrix().to_4x4()
            inverse = np.array(element.inverted())
            local = points @ inverse[:3, :3].T + inverse[:3, 3]
            if el.type == "ELLIPSOID":
                local = local / np.array([el.size_x, el.size_y, el.size_z])
            q = 1 - np.sum(local * local, axis=1) / (el.radius * el.radius)
            s = min(el.stiffness, 10.0) * (-1 if el.use_negative else 1)
            field += s * np.maximum(q, 0) ** 3
    np.save(os.path.join(OUT, "points.npy"), points)
    np.save(os.path.join(OUT, "field.npy"), field)
    a.data.resolution = 0.05   # the viewport's tessellation, which to_mesh gives
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = a.evaluated_get(depsgraph).to_mesh()
    vertices = np.array([list(a.evaluated_get(depsgraph).matrix_world @ v.co)
                         for v in mesh.vertices])
    np.save(os.path.join(OUT, "vertices.npy"), vertices)
    result["threshold"] = a.data.threshold
    result["resolution"] = a.data.resolution


def case_round_trip():
    """Exports a saved .blend, renders it with F12 (to an EXR) in this process; a second
    Blender process opens the .blend and exports again (case export_again)."""
    scene = bs.empty_scene(48, 36)
    bs.add_camera(scene)
    a, b = bs.sculpture(scene)
    a.data.materials.append(bs.principled(
        "Marble", **{"Base Color": (0.9, 0.88, 0.85, 1), "Subsurface": 0.3,
                     "Subsurface Color": (0.9, 0.85, 0.8, 1)}))
    bs.add_sun(scene)
    bs.set_world(scene)
    scene.nimbus.spp = 6
    scene.nimbus.seed = 3
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "scene.blend"))
    export(os.path.join(OUT, "first.json"))
    render(os.path.join(OUT, "f12.exr"))


def case_export_again():
    bpy.ops.wm.open_mainfile(filepath=os.path.join(OUT, "scene.blend"))
    import addon_utils
    addon_utils.enable("nimbus_blender", default_set=True)
    export(os.path.join(OUT, "second.json"))
    # Outputs never replace inputs: the .blend itself is refused, in one line.
    ok, message = reports_of(lambda: export(os.path.join(OUT, "scene.blend")))
    result["export_over_blend"] = [ok, message]
    result["leftover_temporary_files"] = [n for n in os.listdir(OUT) if n.startswith(".nimbus")]


def case_camera():
    """Small emissive balls at known points, rendered by F12 with several cameras; Blender's own
    projection (world_to_camera_view) of their centres."""
    from bpy_extras.object_utils import world_to_camera_view
    configs = [("PERSP", "AUTO", 160, 120, 35.0), ("PERSP", "AUTO", 120, 160, 50.0),
               ("PERSP", "HORIZONTAL", 120, 160, 28.0), ("PERSP", "VERTICAL", 160, 120, 40.0),
               ("ORTHO", "AUTO", 160, 120, 0.0), ("ORTHO", "VERTICAL", 120, 160, 0.0)]
    centres = [(0.0, 0.0, 0.0), (1.1, 0.3, 0.6), (-0.9, -0.4, -0.5), (0.5, 0.8, -0.7)]
    result["configs"] = []
    for index, (kind, fit, w, h, lens) in enumerate(configs):
        scene = bs.empty_scene(w, h)
        scene.render.resolution_percentage = 50   # the film is half the resolution
        scene.render.resolution_x, scene.render.resolution_y = 2 * w, 2 * h
        cam = bs.add_camera(scene, location=(0.7, -5.0, 1.5), target=(0.1, 0.0, 0.1),
                            lens=lens or 35.0, kind=kind)
        cam.data.sensor_fit = fit
        cam.data.sensor_width, cam.data.sensor_height = 36.0, 24.0
        cam.data.ortho_scale = 3.5
        emissive = bs.node_material("Light", "ShaderNodeEmission", Strength=1.0)
        for i, c in enumerate(centres):
            obj = bs.add_metaball(scene, f"Dot{i}", [{"co": (0, 0, 0), "radius": 0.2,
                                                      "stiffness": 2.0}], location=c)
            obj.data.materials.append(emissive)
        scene.nimbus.spp = 16
        path = os.path.join(OUT, f"camera{index}.exr")
        render(path)
        projected = [list(world_to_camera_view(scene, cam, obj.location))
                     for obj in [bpy.data.objects[f"Dot{i}"] for i in range(len(centres))]]
        result["configs"].append({"kind": kind, "fit": fit, "width": w, "height": h,
                                  "image": path, "projected": projected})


def case_lights():
    """One light at a time over a flat, wide metaball floor (diffuse, albedo 0.8), seen from
    above by an orthographic camera: F12 with nimbus and with Cycles, same scene."""
    result["lights"] = []
    for kind, radius in [("POINT", 0.0), ("POINT", 0.25), ("SUN", 0.0), ("SPOT", 0.0)]:
        scene = bs.empty_scene(8, 8)
        cam = bs.add_camera(scene, location=(0, 0, 1.0), target=(0, 0, -1.0), kind="ORTHO")
        cam.data.ortho_scale = 0.3
        floor = bs.add_metaball(scene, "Floor", [
            {"type": "ELLIPSOID", "co": (0, 0, -1.0), "radius": 1.0, "size": (6.0, 6.0, 1.0),
             "stiffness": 2.0}], threshold=0.6)
        material = bs.node_material("White", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1))
        floor.data.materials.append(material)
        floor.data.render_resolution = 0.1   # Cycles' mesh of it: flat where the camera looks
        data = bpy.data.lights.new("Light", kind)
        data.energy = 3.0 if kind == "SUN" else 500.0
        data.color = (1.0, 0.8, 0.6)
        data.shadow_soft_size = radius
        if kind == "SUN":
            data.angle = 0.0
        if kind == "SPOT":
            data.spot_size = math.radians(60)
        light = bpy.data.objects.new("Light", data)
        scene.collection.objects.link(light)
        light.location = (0.0, 0.0, 2.5)
        scene.world = None
        scene.nimbus.spp = 64
        path = os.path.join(OUT, f"light_{kind}_{radius}_nimbus.exr")
        render(path)
        scene.render.engine = "CYCLES"
        scene.cycles.samples = 64
        scene.cycles.use_denoising = False
        scene.cycles.max_bounces = 0
        cycles = os.path.join(OUT, f"light_{kind}_{radius}_cycles.exr")
        render(cycles)
        # The floor's top: where the free form crosses the z axis (Blender's mesh is close).
        result["lights"].append({"kind": kind, "radius": radius, "nimbus": path, "cycles": cycles})


def case_volume_emission():
    """A metaball slab filled with an absorbing, emitting Principled Volume (an emission colour,
    then a blackbody), seen face-on by an orthographic camera: F12 with nimbus and with Cycles."""
    result["volumes"] = []
    for name, inputs in [("colour", {"Emission Strength": 2.0,
                                     "Emission Color": (1.0, 0.5, 0.25, 1.0)}),
                         ("blackbody", {"Blackbody Intensity": 1.0, "Temperature": 2500.0}),
                         # Density 0: it neither absorbs nor scatters, and emits all the same.
                         ("glow", {"Density": 0.0, "Emission Strength": 0.5,
                                   "Emission Color": (1.0, 0.5, 0.25, 1.0)})]:
        scene = bs.empty_scene(8, 8)
        cam = bs.add_camera(scene, location=(0, 0, 3.0), target=(0, 0, 0), kind="ORTHO")
        cam.data.ortho_scale = 0.2
        slab = bs.add_metaball(scene, "Slab", [
            {"type": "ELLIPSOID", "co": (0, 0, 0), "radius": 1.0, "size": (8.0, 8.0, 0.5),
             "stiffness": 2.0}], threshold=0.6)
        slab.data.render_resolution = 0.05
        slab.data.materials.append(bs.node_material(
            "Glow", "ShaderNodeVolumePrincipled", output="Volume",
            **{"Density": 20.0, "Color": (0.0, 0.0, 0.0, 1.0),
               "Absorption_Color": (0.0, 0.0, 0.0, 1.0),
               **{k.replace(" ", "_"): v for k, v in inputs.items()}}))
        scene.world = None
        scene.nimbus.spp = 16
        path = os.path.join(OUT, f"{name}_nimbus.exr")
        render(path)
        scene.render.engine = "CYCLES"
        scene.cycles.samples = 16
        scene.cycles.use_denoising = False
        cycles = os.path.join(OUT, f"{name}_cycles.exr")
        render(cycles)
        result["volumes"].append({"name": name, "nimbus": path, "cycles": cycles})


def case_fire():
    """The flame of scenes/vdb/vdb_fire.vdb as a VDB volume object that only glows: a Principled
    Volume of density 0 whose blackbody reads the temperature grid (Temperature 1: the grid holds
    kelvin), seen along z by an orthographic camera: F12 with nimbus and with Cycles."""
    scene = bs.empty_scene(12, 12)
    cam = bs.add_camera(scene, location=(0, 0.8, 5.0), target=(0, 0.8, 0), kind="ORTHO")
    cam.data.ortho_scale = 1.6
    data = bpy.data.volumes.new("Fire")
    data.filepath = ARGS[2]
    obj = bpy.data.objects.new("Fire", data)
    scene.collection.objects.link(obj)
    obj.data.materials.append(bs.node_material(
        "Flame", "ShaderNodeVolumePrincipled", output="Volume", Density=0.0,
        Blackbody_Intensity=1.0, Temperature=1.0, Temperature_Attribute="temperature"))
    scene.world = None
    scene.nimbus.spp = 64
    export(os.path.join(OUT, "fire.json"))
    path = os.path.join(OUT, "fire_nimbus.exr")
    render(path)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 64
    scene.cycles.use_denoising = False
    cycles = os.path.join(OUT, "fire_cycles.exr")
    render(cycles)
    result["fire"] = {"nimbus": path, "cycles": cycles}


def case_world():
    scene = bs.empty_scene(16, 12)
    bs.add_camera(scene)
    bs.set_world(scene, color=(0.3, 0.5, 0.7), strength=2.5)
    scene.nimbus.spp = 2
    render(os.path.join(OUT, "world.exr"))
    result["expected"] = [0.3 * 2.5, 0.5 * 2.5, 0.7 * 2.5]
    # A linked colour (a texture) is reported and its own value used.
    tree = scene.world.node_tree
    sky = tree.nodes.new("ShaderNodeTexSky")
    tree.links.new(sky.outputs[0], tree.nodes["Background"].inputs["Color"])
    export(os.path.join(OUT, "linked.json"))


def case_volume():
    """A VDB volume object with a Principled Volume, moved and scaled; exported and rendered."""
    vdb = ARGS[2]
    scene = bs.empty_scene(40, 30)
    bs.add_camera(scene, location=(0, -9, 2), target=(0, 0, 0))
    bs.add_sun(scene)
    bs.set_world(scene, color=(0.3, 0.35, 0.4))
    data = bpy.data.volumes.new("Cloud")
    data.filepath = vdb
    obj = bpy.data.objects.new("Cloud", data)
    scene.collection.objects.link(obj)
    obj.location = (0.3, 0.2, -0.1)
    obj.rotation_euler = (0.0, 0.0, 0.4)
    obj.scale = (1.5, 1.5, 1.5)
    material = bs.node_material("Smoke", "ShaderNodeVolumePrincipled", output="Volume",
                                Density=4.0, Color=(0.9, 0.8, 0.7, 1),
                                Absorption_Color=(0.25, 0.25, 0.25, 1))
    obj.data.materials.append(material)
    scene.nimbus.spp = 4
    export(os.path.join(OUT, "scene.json"))
    render(os.path.join(OUT, "f12.exr"))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    corners = [list(obj.evaluated_get(depsgraph).matrix_world @ __import__("mathutils").Vector(c))
               for c in obj.bound_box]
    result["world_corners"] = corners


def case_bad_input():
    """Objects nimbus leaves out, an unreadable VDB and a cancelled render: one line each, and
    Blender goes on (this script renders again after each)."""
    scene = bs.empty_scene(16, 12)
    bs.add_camera(scene)
    bs.set_world(scene)
    bpy.ops.mesh.primitive_cube_add()
    bpy.ops.curve.primitive_bezier_curve_add()
    bs.add_metaball(scene, "Blob", [{"co": (0, 0, 0), "radius": 1.0},
                                    {"type": "CAPSULE", "co": (1, 0, 0), "radius": 0.5}])
    scene.nimbus.spp = 2
    render(os.path.join(OUT, "left_out.exr"))
    from nimbus_blender import convert
    _, warnings = convert.scene_document(bpy.context.evaluated_depsgraph_get(), scene.nimbus)
    result["warnings"] = warnings

    data = bpy.data.volumes.new("Broken")
    data.filepath = os.path.join(OUT, "broken.vdb")
    with open(data.filepath, "wb") as f:
        f.write(b"not a vdb file at all")
    obj = bpy.data.objects.new("Broken", data)
    scene.collection.objects.link(obj)
    ok, message = reports_of(lambda: render(os.path.join(OUT, "broken.exr")))
    result["broken_vdb"] = [ok, message]
    bpy.data.objects.remove(obj)

    # Esc: the engine asks Blender's test_break between and during passes; here the answer is
    # "stop" once three passes are shown, as when Esc is pressed then.
    from nimbus_blender import engine
    calls = {"passes": 0}
    original_rgba = engine._rgba

    def counting_rgba(image):
        calls["passes"] += 1
        return original_rgba(image)

    original_should_stop = engine.should_stop
    engine.should_stop = lambda engine_: calls["passes"] >= 3
    engine._rgba = counting_rgba
    scene.nimbus.spp = 64
    ok, message = reports_of(lambda: render(os.path.join(OUT, "cancelled.exr")))
    engine.should_stop = original_should_stop
    engine._rgba = original_rgba
    result["cancelled"] = [ok, message, calls["passes"]]
    export(os.path.join(OUT, "cancelled.json"))
    scene.nimbus.spp = 2
    render(os.path.join(OUT, "after.exr"))

    # Scenes nimbus cannot render, and exports it cannot write: one line each.
    bpy.ops.export_scene.nimbus(filepath=os.path.join(OUT, "before_camera.json"))
    scene.camera.data.type = "PANO"
    result["panoramic_export"] = reports_of(
        lambda: export(os.path.join(OUT, "pano.json")))
    scene.camera = None
    result["no_camera"] = reports_of(lambda: export(os.path.join(OUT, "none.json")))
    result["missing_folder"] = reports_of(
        lambda: export(os.path.join(OUT, "no", "such", "folder", "scene.json")))
    result["written"] = sorted(n for n in os.listdir(OUT) if n.endswith(".json"))
    result["blender_went_on"] = True


def case_executable():
    """The executable back end (the add-on's preference): the same pixels as the module's."""
    scene = bs.empty_scene(32, 24)
    bs.add_camera(scene)
    bs.sculpture(scene)
    bs.add_sun(scene)
    bs.set_world(scene)
    scene.nimbus.spp = 4
    render(os.path.join(OUT, "module.exr"))
    prefs = bpy.context.preferences.addons["nimbus_blender"].preferences
    prefs.backend = "EXECUTABLE"
    render(os.path.join(OUT, "executable.exr"))
    export(os.path.join(OUT, "scene.json"))


def case_sculpture():
    """The repository's scene: opened, exported; its warnings."""
    import addon_utils
    bpy.ops.wm.open_mainfile(filepath=ARGS[2])
    addon_utils.enable("nimbus_blender", default_set=True)
    export(os.path.join(OUT, "sculpture.json"))
    from nimbus_blender import convert
    _, warnings = convert.scene_document(bpy.context.evaluated_depsgraph_get(),
                                         bpy.context.scene.nimbus)
    result["warnings"] = warnings
    result["engine"] = bpy.context.scene.render.engine


globals()["case_" + CASE]()
with open(os.path.join(OUT, "result.json"), "w") as f:
    json.dump(result, f, indent=1)

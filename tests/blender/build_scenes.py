"""Blender scenes for the add-on's tests, built by script (run inside Blender)."""
import math

import bpy


def empty_scene(width=64, height=48):
    """An empty scene rendered by nimbus at the given resolution (factory settings, then the
    add-on enabled again: resetting the preferences disables it)."""
    import addon_utils
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("nimbus_blender", default_set=True)
    scene = bpy.context.scene
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.engine = "NIMBUS"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.view_settings.view_transform = "Standard"
    return scene


def add_camera(scene, location=(0.0, -6.0, 1.0), target=(0.0, 0.0, 0.0), lens=35.0,
               kind="PERSP"):
    data = bpy.data.cameras.new("Camera")
    data.type = kind
    data.lens = lens
    obj = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(obj)
    obj.location = location
    direction = [t - l for t, l in zip(target, location)]
    from mathutils import Vector
    obj.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = obj
    return obj


def add_metaball(scene, name, elements, threshold=0.6, location=(0, 0, 0), rotation=(0, 0, 0),
                 scale=(1, 1, 1)):
    """elements: dicts with type, co, radius, stiffness, negative, size (ellipsoid), rotation
    (quaternion w, x, y, z)."""
    data = bpy.data.metaballs.new(name)
    data.threshold = threshold
    for e in elements:
        el = data.elements.new(type=e.get("type", "BALL"))
        el.co = e.get("co", (0, 0, 0))
        el.radius = e.get("radius", 1.0)
        el.stiffness = e.get("stiffness", 2.0)
        el.use_negative = e.get("negative", False)
        if "size" in e:
            el.size_x, el.size_y, el.size_z = e["size"]
        if "rotation" in e:
            el.rotation = e["rotation"]
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = rotation
    obj.scale = scale
    return obj


def principled(name, **inputs):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    node = material.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    return material


def node_material(name, node_type, output="Surface", **inputs):
    """A material whose only node is `node_type` (e.g. "ShaderNodeEmission") into `output`."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    node = nodes.new(node_type)
    for key, value in inputs.items():
        node.inputs[key.replace("_", " ")].default_value = value
    material.node_tree.links.new(node.outputs[0], nodes["Material Output"].inputs[output])
    return material


def add_sun(scene, strength=3.0, rotation=(math.radians(40), 0, math.radians(30))):
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = strength
    data.angle = 0.0
    obj = bpy.data.objects.new("Sun", data)
    scene.collection.objects.link(obj)
    obj.rotation_euler = rotation
    return obj


def set_world(scene, color=(0.2, 0.25, 0.3), strength=1.0):
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    scene.world = world
    return world


def sculpture(scene):
    """Balls, an ellipsoid, a negative element, and a second object of the family, transformed."""
    a = add_metaball(scene, "Blob", [
        {"co": (0, 0, 0), "radius": 1.2, "stiffness": 2.0},
        {"co": (0.9, 0.2, 0.3), "radius": 0.8, "stiffness": 3.0},
        {"type": "ELLIPSOID", "co": (-0.7, 0.1, 0.2), "radius": 0.9, "size": (1.6, 0.7, 0.9),
         "rotation": (0.9238795, 0.0, 0.3826834, 0.0)},
        {"co": (0.2, -0.6, 0.5), "radius": 0.6, "stiffness": 4.0, "negative": True},
    ], threshold=0.6, location=(0.1, 0.0, 0.0), rotation=(0.2, 0.1, 0.3))
    b = add_metaball(scene, "Blob.001", [
        {"co": (0, 0, 0), "radius": 0.7, "stiffness": 2.5},
        {"type": "ELLIPSOID", "co": (0.3, 0, 0.2), "radius": 0.5, "size": (1.0, 2.0, 0.8)},
    ], location=(0.4, 0.3, 1.0), rotation=(0.5, -0.2, 0.0), scale=(1.2, 0.8, 1.0))
    return a, b

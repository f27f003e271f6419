"""Builds scenes/blender/sculpture.blend: a metaball sculpture in marble, on a metaball plinth,
under the sun, before a cloud (the repository's VDB), rendered by nimbus (docs/blender.md).

    blender -b --factory-startup --python-exit-code 1 -P scenes/blender/make_sculpture.py
    BLENDER_USER_SCRIPTS=build/blender blender -b --addons nimbus_blender scenes/blender/sculpture.blend \
        -o //sculpture_ -F PNG -f 1

Every number here is the scene: run it again and the .blend exports to the same scene file.
"""
import math
import os

import bpy
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = 480, 270
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"


def metaball(name, elements, threshold=0.6):
    data = bpy.data.metaballs.new(name)
    data.threshold = threshold
    data.resolution = 0.1
    data.render_resolution = 0.05
    for kind, co, radius, stiffness, extra in elements:
        el = data.elements.new(type=kind)
        el.co, el.radius, el.stiffness = co, radius, stiffness
        for key, value in extra.items():
            setattr(el, key, value)
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    return obj


def material(name, inputs=None, volume=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    out = nodes["Material Output"]
    if inputs is None:
        nodes.remove(nodes["Principled BSDF"])
    else:
        for key, value in inputs.items():
            nodes["Principled BSDF"].inputs[key].default_value = value
    if volume is not None:
        node = nodes.new("ShaderNodeVolumePrincipled")
        for key, value in volume.items():
            node.inputs[key].default_value = value
        links.new(node.outputs[0], out.inputs["Volume"])
    return m


# The sculpture: a reclining form of ellipsoids, pierced by negative balls.
sculpture = metaball("Sculpture", [
    ("ELLIPSOID", (0.0, 0.0, 0.6), 1.3, 2.0, {"size_x": 1.7, "size_y": 0.7, "size_z": 0.6}),
    ("ELLIPSOID", (1.25, 0.1, 1.1), 1.0, 2.5, {"size_x": 0.7, "size_y": 0.8, "size_z": 1.4,
                                               "rotation": (0.966, 0.0, -0.259, 0.0)}),
    ("ELLIPSOID", (-1.35, -0.1, 0.8), 1.0, 2.5, {"size_x": 1.1, "size_y": 0.8, "size_z": 1.0,
                                                 "rotation": (0.966, 0.0, 0.259, 0.0)}),
    ("BALL", (1.4, 0.1, 2.1), 0.75, 3.0, {}),
    ("BALL", (0.05, 0.0, 0.95), 0.7, 4.0, {"use_negative": True}),
    ("BALL", (-1.4, -0.7, 0.9), 0.55, 4.0, {"use_negative": True}),
])
sculpture.data.materials.append(material("Marble", {
    "Base Color": (0.93, 0.9, 0.85, 1.0), "Subsurface": 0.15,
    "Subsurface Radius": (1.0, 0.75, 0.55), "Subsurface Color": (0.92, 0.88, 0.82, 1.0),
    "Subsurface IOR": 1.5, "Roughness": 0.2}))

plinth = metaball("Plinth", [
    ("ELLIPSOID", (0.0, 0.0, -0.45), 1.0, 2.0, {"size_x": 12.0, "size_y": 12.0, "size_z": 0.5}),
])
plinth.data.materials.append(material("Stone", {"Base Color": (0.45, 0.42, 0.4, 1.0)}))

# The cloud: the repository's VDB cloud as a volume object, behind and around the sculpture.
cloud_data = bpy.data.volumes.new("Cloud")
cloud_data.filepath = "//../vdb/vdb_cloud.vdb"
cloud = bpy.data.objects.new("Cloud", cloud_data)
scene.collection.objects.link(cloud)
cloud.location = (-0.8, 4.5, 2.4)
cloud.rotation_euler = (math.radians(90), 0.0, 0.0)
cloud.scale = (1.3, 1.3, 1.3)
cloud.data.materials.append(material("Cloud", volume={
    "Density": 6.0, "Color": (0.95, 0.96, 1.0, 1.0), "Anisotropy": 0.5}))

sun_data = bpy.data.lights.new("Sun", "SUN")
sun_data.energy = 4.0
sun_data.color = (1.0, 0.93, 0.82)
sun_data.angle = math.radians(0.5)
sun = bpy.data.objects.new("Sun", sun_data)
scene.collection.objects.link(sun)
sun.rotation_euler = (math.radians(50), 0.0, math.radians(-40))

world = bpy.data.worlds.new("Sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.45, 0.65, 1.0)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
scene.world = world

camera_data = bpy.data.cameras.new("Camera")
camera_data.lens = 40
camera = bpy.data.objects.new("Camera", camera_data)
scene.collection.objects.link(camera)
camera.location = (3.6, -6.4, 2.2)
look = Vector((0.0, 0.5, 1.2)) - camera.location
camera.rotation_euler = look.to_track_quat("-Z", "Y").to_euler()
scene.camera = camera

try:
    import addon_utils
    addon_utils.enable("nimbus_blender", default_set=True)
    scene.render.engine = "NIMBUS"
    scene.nimbus.spp = 256
    scene.nimbus.noise_target = 0.05
except Exception as e:   # the .blend is made without the add-on too; F12 then needs it enabled
    print(f"make_sculpture: the nimbus add-on is not enabled ({e}); the render engine is unset")
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(HERE, "sculpture.blend"), compress=True)

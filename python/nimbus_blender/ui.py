"""Settings, panels, preferences and the export operator."""
import json
import os
import tempfile

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from . import convert

_TRACKING = [("spectral-mis", "Spectral MIS", "Hero-wavelength spectral MIS (the default)"),
             ("spectral-history", "Spectral history", "History-aware collision weights"),
             ("spectral-max", "Spectral max", "One free path with the maximum majorant"),
             ("delta", "Delta", "Delta tracking per wavelength")]
_WAVELENGTHS = [("4", "4", ""), ("8", "8", ""), ("12", "12", ""), ("16", "16", "")]


class NimbusSettings(bpy.types.PropertyGroup):
    """The scene's integrator keys (docs/scene-format.md, "integrator")."""
    spp: IntProperty(name="Samples", description="Samples per pixel; with a noise target, the "
                     "most a pixel takes", default=64, min=1, max=1 << 20)
    seed: IntProperty(name="Seed", description="Seed of every random stream", default=0, min=0)
    max_depth: IntProperty(name="Max depth", description="Most scattering events along a path",
                           default=1000, min=1)
    tracking: EnumProperty(name="Tracking", items=_TRACKING, default="spectral-mis",
                           description="Free-path sampling in media")
    spectral: BoolProperty(name="Spectral", default=False,
                           description="Wavelengths sampled per path instead of RGB channels")
    wavelengths: EnumProperty(name="Wavelengths", items=_WAVELENGTHS, default="8",
                              description="Wavelengths per path in spectral mode")
    noise_target: FloatProperty(name="Noise target", default=0.0, min=0.0, max=1.0,
                                precision=3, description="Each 8 x 8 block takes samples until "
                                "its relative error is at most this (0: every pixel takes Samples)")


class NimbusPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__
    backend: EnumProperty(name="Render with", default="AUTO", items=[
        ("AUTO", "Module, else executable", "The nimbus Python module in Blender's interpreter; "
         "the executable when the module cannot be imported"),
        ("EXECUTABLE", "Executable", "Always the nimbus executable (no progressive updates)")])
    module_folder: StringProperty(name="Module folder", subtype="DIR_PATH",
                                  description="A folder holding the nimbus package, when Blender's "
                                  "Python does not find it")
    executable: StringProperty(name="Executable", subtype="FILE_PATH",
                               description="The nimbus executable (default: beside the add-on, "
                               "then PATH)")

    def draw(self, context):
        for name in ("backend", "module_folder", "executable"):
            self.layout.prop(self, name)


class RENDER_PT_nimbus(bpy.types.Panel):
    bl_label = "nimbus"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"NIMBUS"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        settings = context.scene.nimbus
        layout = self.layout
        layout.use_property_split = True
        for name in ("spp", "seed", "noise_target", "max_depth", "tracking", "spectral"):
            layout.prop(settings, name)
        row = layout.row()
        row.enabled = settings.spectral
        row.prop(settings, "wavelengths")


def write_document(path, document):
    """Writes the scene file atomically: a temporary file beside it, then a rename."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    handle, temporary = tempfile.mkstemp(prefix=".nimbus-export-", suffix=".json", dir=folder)
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as f:
            json.dump(document, f, indent=1)
            f.write("\n")
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


def export(context, filepath):
    """Writes the scene file; returns the warnings. Raises ValueError with one line."""
    path = os.path.abspath(bpy.path.abspath(filepath))
    inputs = [bpy.data.filepath] + [bpy.path.abspath(v.filepath) for v in bpy.data.volumes]
    for source in inputs:
        if source and os.path.exists(source) and os.path.exists(path) and \
                os.path.samefile(source, path):
            raise ValueError(f"{path}: is an input of this scene ({source}); choose another file")
    if os.path.isdir(path):
        raise ValueError(f"{path}: is a directory")
    folder = os.path.dirname(path)
    if not os.path.isdir(folder):
        raise ValueError(f"{path}: folder {folder} does not exist")
    document, warnings = convert.scene_document(context.evaluated_depsgraph_get(),
                                                context.scene.nimbus)
    write_document(path, document)
    return warnings


class EXPORT_SCENE_OT_nimbus(bpy.types.Operator, ExportHelper):
    """Export the scene as a nimbus scene file (JSON)"""
    bl_idname = "export_scene.nimbus"
    bl_label = "Export nimbus scene"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def execute(self, context):
        try:
            warnings = export(context, self.filepath)
        except (ValueError, OSError) as e:
            self.report({"ERROR"}, f"nimbus: {e}")
            return {"CANCELLED"}
        for line in warnings:
            self.report({"WARNING"}, f"nimbus: {line}")
        return {"FINISHED"}


def menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_nimbus.bl_idname, text="nimbus (.json)")


def compatible_panels():
    """Blender's own panels that apply to nimbus: dimensions, output, camera, light, world and
    material settings that the conversion reads."""
    names = ["RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output",
             "DATA_PT_lens", "DATA_PT_camera", "DATA_PT_camera_dof",
             "DATA_PT_light", "DATA_PT_EEVEE_light", "DATA_PT_area",
             "EEVEE_MATERIAL_PT_surface", "EEVEE_MATERIAL_PT_volume", "MATERIAL_PT_preview",
             "EEVEE_WORLD_PT_surface", "WORLD_PT_context_world", "DATA_PT_metaball",
             "DATA_PT_mball_texture_space", "DATA_PT_metaball_element", "DATA_PT_volume_file",
             "DATA_PT_volume_grids", "DATA_PT_context_metaball", "DATA_PT_context_volume"]
    panels = [getattr(bpy.types, n) for n in names if hasattr(bpy.types, n)]
    # Panels without COMPAT_ENGINES show for every engine already.
    return [p for p in panels if hasattr(p, "COMPAT_ENGINES")]

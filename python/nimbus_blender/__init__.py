"""nimbus in Blender: F12 renders with nimbus, File > Export writes a nimbus scene file, and
metaballs become the paper's free forms exactly (docs/blender.md)."""

bl_info = {
    "name": "nimbus",
    "author": "the nimbus developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine; File > Export > nimbus (.json)",
    "description": "Renders metaballs as exact free forms and volumes by spectral tracking",
    "category": "Render",
}

import bpy  # noqa: E402

from . import engine, ui  # noqa: E402

_classes = (ui.NimbusSettings, ui.NimbusPreferences, ui.RENDER_PT_nimbus,
            ui.EXPORT_SCENE_OT_nimbus, engine.NimbusRenderEngine)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.nimbus = bpy.props.PointerProperty(type=ui.NimbusSettings)
    bpy.types.TOPBAR_MT_file_export.append(ui.menu_export)
    for panel in ui.compatible_panels():
        panel.COMPAT_ENGINES.add(engine.NimbusRenderEngine.bl_idname)


def unregister():
    for panel in ui.compatible_panels():
        panel.COMPAT_ENGINES.discard(engine.NimbusRenderEngine.bl_idname)
    bpy.types.TOPBAR_MT_file_export.remove(ui.menu_export)
    del bpy.types.Scene.nimbus
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)

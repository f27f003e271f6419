"""The render engine: F12 renders the scene with nimbus into Blender's render result."""
import shutil
import time

import bpy
import numpy as np

from . import backend, convert


def preferences(context):
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon is not None else None


def should_stop(engine):
    """Esc: Blender's test_break (a module function, so that the tests can press Esc)."""
    return engine.test_break()


def _rgba(image):
    """A (h, w, 3) image, top row first, as the render result's rows: bottom first, with alpha."""
    h, w, _ = image.shape
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = image[::-1]
    return rgba.reshape(h * w, 4)


class NimbusRenderEngine(bpy.types.RenderEngine):
    bl_idname = "NIMBUS"
    bl_label = "nimbus"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False

    def render(self, depsgraph):
        started = time.monotonic()
        scene = depsgraph.scene
        try:
            document, warnings = convert.scene_document(depsgraph, scene.nimbus)
        except convert.ConversionError as e:
            self.report({"ERROR"}, f"nimbus: {e}")
            return
        for line in warnings:
            self.report({"WARNING"}, f"nimbus: {line}")
        prefs = preferences(bpy.context)
        module = None
        if prefs is None or prefs.backend != "EXECUTABLE":
            module = backend.load_module(prefs.module_folder if prefs else "")
        # Blender's fixed thread count, else every core; no pixel depends on it.
        threads = scene.render.threads if scene.render.threads_mode == "FIXED" else None
        if module is not None:
            self.render_with_module(module, document, started, threads)
        else:
            self.render_with_executable(document, prefs)

    def render_with_module(self, nimbus, document, started, threads):
        try:
            scene = nimbus.load_dict(document, source="<blender>")
            film = nimbus.Film(scene)
        except (ValueError, RuntimeError) as e:
            self.report({"ERROR"}, f"nimbus: {e}")
            return
        width, height = document["film"]["width"], document["film"]["height"]
        spp = document["integrator"]["spp"]
        result = self.begin_result(0, 0, width, height)
        first = []

        def on_pass(film, samples):
            result.layers[0].passes["Combined"].rect = _rgba(film.image())
            self.update_result(result)
            self.update_progress(samples / spp)
            self.update_stats("", f"nimbus: {samples} / {spp} samples per pixel")
            if not first:
                first.append(time.monotonic() - started)

        try:
            done = backend.render_progressive(nimbus, scene, film, spp,
                                              lambda: should_stop(self), on_pass, threads)
        except (ValueError, RuntimeError) as e:
            self.end_result(result)
            self.report({"ERROR"}, f"nimbus: {e}")
            return
        self.end_result(result)
        if done < spp:
            self.report({"WARNING"},
                        f"nimbus: render cancelled at {done} of {spp} samples per pixel")
        else:
            samples = f"{spp} spp"
            if document["integrator"].get("noise_target"):
                samples = (f"{film.samples().mean():.1f} spp on average (noise target "
                           f"{document['integrator']['noise_target']:g}, at most {spp})")
            self.report({"INFO"}, f"nimbus: {samples} in {time.monotonic() - started:.2f} s, "
                                  f"first pixels after {first[0]:.2f} s")

    def render_with_executable(self, document, prefs):
        executable = backend.find_executable(prefs.executable if prefs else "")
        if executable is None:
            self.report({"ERROR"}, "nimbus: neither the nimbus module nor the nimbus executable "
                                   "was found (set them in the add-on's preferences)")
            return
        width, height = document["film"]["width"], document["film"]["height"]
        self.update_stats("", f"nimbus: rendering with {executable}")
        folder = None
        try:
            path, folder = backend.render_with_executable(executable, document,
                                                          lambda: should_stop(self))
            if path is None:
                self.report({"WARNING"}, "nimbus: render cancelled")
                return
            image = bpy.data.images.load(path, check_existing=False)
            try:
                image.colorspace_settings.name = "Non-Color"
                pixels = np.empty(width * height * 4, dtype=np.float32)
                image.pixels.foreach_get(pixels)
            finally:
                bpy.data.images.remove(image)
            result = self.begin_result(0, 0, width, height)
            result.layers[0].passes["Combined"].rect = pixels.reshape(width * height, 4)
            self.end_result(result)
        except RuntimeError as e:
            self.report({"ERROR"}, f"nimbus: {e}")
        finally:
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)

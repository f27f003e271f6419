"""A Blender scene as a nimbus scene document (docs/blender.md has the table of conversions).

`scene_document(depsgraph, settings)` reads an evaluated depsgraph and returns (document,
warnings): the dict in the scene-file schema (docs/scene-format.md) and one line per thing it
left out or approximated. Problems that leave nothing to render raise ConversionError. The
document depends on the scene only: objects in name order, numbers as Blender stores them, so
that exporting one file twice gives the same bytes.
"""
import math
import os

import numpy as np

from . import metaball


# The Principled BSDF's inputs that Blender 4.0 renamed or dropped: the name to read instead.
_RENAMED = {"Transmission": "Transmission Weight", "Subsurface": "Subsurface Weight",
            "Emission": "Emission Color", "Subsurface Color": "Base Color",
            "Subsurface IOR": "IOR"}


class ConversionError(ValueError):
    """A scene nimbus cannot render: no camera, a panoramic camera."""


# Blender's default colour of an object without a material (its viewport and Cycles grey).
DEFAULT_ALBEDO = 0.8


def _floats(values):
    return [float(v) for v in values]


def _matrix(m):
    return np.array([[float(m[i][j]) for j in range(4)] for i in range(4)], dtype=np.float64)


def _round(x):
    """Numbers computed here in double, rounded to 12 significant digits: a file that reads well
    and the same bytes from the same scene."""
    return float(f"{x:.12g}")


def _vector(v):
    return [_round(float(c)) for c in v]


def _rgb(color, scale=1.0):
    return [_round(float(color[i]) * scale) for i in range(3)]


class Converter:
    def __init__(self, depsgraph, settings):
        self.depsgraph = depsgraph
        self.scene = depsgraph.scene_eval
        self.settings = settings
        self.warnings = []
        self.shapes = {}
        self.media = {}
        self.objects = []
        self.lights = []

    def warn(self, line):
        if line not in self.warnings:
            self.warnings.append(line)

    # --- film and camera ------------------------------------------------------------------
    def film(self):
        r = self.scene.render
        width = r.resolution_x * r.resolution_percentage // 100
        height = r.resolution_y * r.resolution_percentage // 100
        if width < 1 or height < 1:
            raise ConversionError(f"render resolution {width} x {height}: must be at least 1 x 1")
        if r.pixel_aspect_x != r.pixel_aspect_y:
            self.warn(f"render: pixel aspect {r.pixel_aspect_x}:{r.pixel_aspect_y} left out; "
                      "nimbus renders square pixels")
        return {"width": width, "height": height}

    def camera(self, film):
        cam = self.scene.camera
        if cam is None:
            raise ConversionError("the scene has no camera")
        data = cam.data
        if data.type == "PANO":
            raise ConversionError(f'camera "{cam.name}": panoramic cameras are not supported')
        m = _matrix(cam.matrix_world)
        eye = m[:3, 3]
        forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
        up = m[:3, 1] / np.linalg.norm(m[:3, 1])
        w, h = film["width"], film["height"]
        fit = data.sensor_fit
        horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and w >= h)
        out = {"type": "perspective" if data.type == "PERSP" else "orthographic",
               "from": _vector(eye), "to": _vector(eye + forward), "up": _vector(up)}
        if data.type == "PERSP":
            sensor = data.sensor_height if fit == "VERTICAL" else data.sensor_width
            half = sensor / (2.0 * data.lens)   # tan of half the angle along the fitted side
            tan_v = half * h / w if horizontal else half
            out["fov"] = _round(math.degrees(2.0 * math.atan(tan_v)))
        else:
            out["width"] = _round(data.ortho_scale if horizontal else data.ortho_scale * w / h)
        if data.shift_x != 0 or data.shift_y != 0:
            self.warn(f'camera "{cam.name}": lens shift left out')
        if data.dof.use_dof:
            self.warn(f'camera "{cam.name}": depth of field left out (nimbus has a pinhole camera)')
        return out

    # --- integrator ---------------------------------------------------------------------------
    def integrator(self):
        s = self.settings
        out = {"spp": int(s.spp), "seed": int(s.seed), "max_depth": int(s.max_depth),
               "tracking": s.tracking}
        if s.noise_target > 0:
            out["noise_target"] = _round(s.noise_target)
        return out

    def spectrum(self):
        s = self.settings
        if s.spectral:
            return {"mode": "spectral", "wavelengths": int(s.wavelengths)}
        return {"mode": "rgb"}

    # --- world and lights ---------------------------------------------------------------------
    def world(self):
        world = self.scene.world
        if world is None:
            return
        color, strength = world.color, 1.0
        if world.use_nodes and world.node_tree is not None:
            output = _active_output(world.node_tree, "OUTPUT_WORLD")
            node = _linked_node(output, "Surface") if output else None
            if node is None:
                return
            if node.type != "BACKGROUND":
                self.warn(f'world "{world.name}": a {node.name} node left out; only a Background '
                          "node's colour and strength are converted")
                return
            color = self.input_value(node, "Color", f'world "{world.name}"')
            strength = self.input_value(node, "Strength", f'world "{world.name}"')
        radiance = _rgb(color, strength)
        if any(c > 0 for c in radiance):
            self.lights.append({"type": "environment", "radiance": radiance})

    def light(self, obj, matrix):
        data = obj.data
        where = f'light "{obj.name}"'
        power = _rgb(data.color, data.energy)
        m = _matrix(matrix)
        position = _vector(m[:3, 3])
        if data.type == "SUN":
            direction = -m[:3, 2]
            self.lights.append({"type": "directional", "direction": _vector(direction),
                                "irradiance": power})
            if math.degrees(data.angle) > 1.0:
                self.warn(f"{where}: the sun's angle {math.degrees(data.angle):.3g}° left out; "
                          "nimbus's sun is a direction (sharp shadows)")
            return
        if data.type == "AREA":
            area = _area(data)
            radius = math.sqrt(area / math.pi)
            self.warn(f"{where}: an area light becomes a sphere light of the same area and power")
        else:
            radius = float(data.shadow_soft_size)
            if data.type == "SPOT":
                self.warn(f"{where}: a spot light becomes a point light of the same intensity; "
                          "its cone is left out")
        if radius > 0:
            # A sphere of radius r and radiance L emits 4 pi^2 r^2 L.
            self.lights.append({"type": "sphere", "center": position, "radius": _round(radius),
                                "radiance": [_round(p / (4 * math.pi ** 2 * radius ** 2))
                                             for p in power]})
        else:
            # A point of power P has intensity P / (4 pi) in every direction.
            self.lights.append({"type": "point", "position": position,
                                "intensity": [_round(p / (4 * math.pi)) for p in power]})

    # --- materials ---------------------------------------------------------------------------
    def input_value(self, node, name, where):
        """A socket's value; Blender 4's names of the Principled BSDF's inputs are read too, and
        its inputs that Blender 4 dropped fall back to the ones that replace them."""
        socket = node.inputs.get(name)
        if socket is None:
            socket = node.inputs[_RENAMED[name]]
        if socket.is_linked:
            self.warn(f"{where}: the {node.name} node's {name} input is linked; its own value is "
                      "used (textures and node networks are left out)")
        value = socket.default_value
        try:
            return [float(v) for v in value]
        except TypeError:
            return float(value)

    def surface(self, obj, name):
        """(surface, medium or None) for an object's material."""
        material = obj.active_material
        where = f'object "{obj.name}"'
        if material is None:
            return {"type": "diffuse", "albedo": DEFAULT_ALBEDO}, None
        where = f'material "{material.name}"'
        if not material.use_nodes or material.node_tree is None:
            return {"type": "diffuse", "albedo": _rgb(material.diffuse_color)}, None
        output = _active_output(material.node_tree, "OUTPUT_MATERIAL")
        node = _linked_node(output, "Surface") if output else None
        volume = _linked_node(output, "Volume") if output else None
        if volume is not None:
            # A volume shader fills the object: index-matched without a surface shader, inside a
            # glass boundary with a transmissive one.
            medium, _ = self.volume_medium(obj, where)
            if node is None:
                self.media[name] = medium
                return {"type": "none"}, name
            if node.type in ("BSDF_PRINCIPLED", "BSDF_GLASS") and self.transmissive(node, where):
                surface, _ = self.surface_of_node(node, where, name)
                self.media[name] = medium
                return surface, name
            self.warn(f"{where}: the volume shader is left out: behind an opaque surface no light "
                      "reaches it")
        if node is None:
            return {"type": "diffuse", "albedo": 0.0}, None
        return self.surface_of_node(node, where, name)

    def transmissive(self, node, where):
        return node.type == "BSDF_GLASS" or self.input_value(node, "Transmission", where) >= 0.5

    def surface_of_node(self, node, where, name):
        kind = node.type
        if kind == "BSDF_PRINCIPLED":
            return self.principled(node, where, name)
        if kind == "BSDF_DIFFUSE":
            return {"type": "diffuse", "albedo": _rgb(self.input_value(node, "Color", where))}, None
        if kind == "BSDF_GLASS":
            surface = {"type": "dielectric", "ior": _round(self.input_value(node, "IOR", where))}
            roughness = self.input_value(node, "Roughness", where) ** 2
            if roughness > 0:
                surface["roughness"] = _round(roughness)
            return surface, None
        if kind == "EMISSION":
            color = self.input_value(node, "Color", where)
            strength = self.input_value(node, "Strength", where)
            return {"type": "emissive", "radiance": _rgb(color, strength)}, None
        self.warn(f"{where}: a {node.name} node is not converted; the object is diffuse grey")
        return {"type": "diffuse", "albedo": DEFAULT_ALBEDO}, None

    def principled(self, node, where, name):
        base = self.input_value(node, "Base Color", where)
        emission = self.input_value(node, "Emission", where)
        emission_strength = self.input_value(node, "Emission Strength", where)
        if self.input_value(node, "Alpha", where) < 1:
            self.warn(f"{where}: alpha left out (the object is opaque)")
        radiance = _rgb(emission, emission_strength)
        if any(c > 0 for c in radiance):
            return {"type": "emissive", "radiance": radiance}, None
        roughness = self.input_value(node, "Roughness", where) ** 2   # GGX alpha (Blender's r^2)
        if self.input_value(node, "Metallic", where) >= 0.5:
            # Gulbrandsen 2014 with a white edge tint: eta, k whose head-on reflectance is the base
            # colour, as the Principled BSDF's Schlick Fresnel (white at grazing angles).
            r = [min(max(c, 0.0), 0.999) for c in base[:3]]
            eta = [_round((1 - c) / (1 + c)) for c in r]
            eta = [max(e, 1e-3) for e in eta]
            k = [_round(2 * math.sqrt(c) / (1 + c)) for c in r]
            return {"type": "conductor", "eta": eta, "k": k, "roughness": _round(roughness)}, None
        if self.input_value(node, "Transmission", where) >= 0.5:
            surface = {"type": "dielectric", "ior": _round(max(self.input_value(node, "IOR", where),
                                                               1.0))}
            if roughness > 0:
                surface["roughness"] = _round(roughness)
            return surface, None
        subsurface = self.input_value(node, "Subsurface", where)
        if subsurface > 0:
            return self.subsurface(node, where, name, base, subsurface)
        return {"type": "diffuse", "albedo": _rgb([min(max(c, 0.0), 1.0) for c in base])}, None

    def subsurface(self, node, where, name, base, weight):
        """Principled subsurface as a medium inside a smooth dielectric boundary: the mean free
        path d = Subsurface x Radius per channel and the albedo A = the colour mixed by the weight,
        inverted to a single-scattering albedo and extinction by Chiang et al. 2016's fit."""
        radius = self.input_value(node, "Subsurface Radius", where)
        color = self.input_value(node, "Subsurface Color", where)
        anisotropy = self.input_value(node, "Subsurface Anisotropy", where)
        ior = max(self.input_value(node, "Subsurface IOR", where), 1.0)
        # Blender 3 scales the radius by the weight; Blender 4 by its Subsurface Scale.
        scale = (self.input_value(node, "Subsurface Scale", where)
                 if "Subsurface Scale" in node.inputs else weight)
        albedo = [min(max(weight * color[i] + (1 - weight) * base[i], 0.0), 0.999)
                  for i in range(3)]
        sigma_a, sigma_s = [], []
        for i in range(3):
            A = albedo[i]
            alpha = 1 - math.exp(-5.09406 * A + 2.61188 * A * A - 4.31805 * A ** 3)
            s = 1.9 - A + 3.5 * (A - 0.8) ** 2
            d = max(scale * radius[i], 1e-6)
            sigma_t = 1.0 / (d * s)
            sigma_s.append(_round(alpha * sigma_t))
            sigma_a.append(_round((1 - alpha) * sigma_t))
        medium = {"sigma_a": sigma_a, "sigma_s": sigma_s}
        if anisotropy != 0:
            medium["phase"] = {"type": "hg", "g": _round(min(max(anisotropy, -0.99), 0.99))}
        self.media[name] = medium
        return {"type": "dielectric", "ior": _round(ior)}, name

    # --- objects ---------------------------------------------------------------------------------
    def metaballs(self, members):
        """One free form per family: the elements of every member, the basis's threshold and
        material (Blender renders a family as its basis object)."""
        families = {}
        for obj, matrix in members:
            families.setdefault(metaball.family_name(obj.name), []).append((obj, matrix))
        for family in sorted(families):
            parts = sorted(families[family], key=lambda p: (metaball.family_rank(p[0].name),
                                                            p[0].name))
            basis = parts[0][0]
            perturbations = []
            for obj, matrix in parts:
                m = _matrix(matrix)
                for index, el in enumerate(obj.data.elements):
                    if el.hide:
                        continue
                    axes, exact = metaball.element_axes(
                        el.type, float(el.radius),
                        (float(el.size_x), float(el.size_y), float(el.size_z)))
                    if not exact:
                        self.warn(f'metaball "{obj.name}": element {index} ({el.type.lower()}) is '
                                  "not a quadric; it is rendered as the closest ellipsoid")
                    world = metaball.element_matrix(m, _floats(el.co), _floats(el.rotation))
                    coefficients = metaball.element_quadric(world, axes, float(el.radius))
                    if not metaball.is_finite_quadric(coefficients):
                        self.warn(f'metaball "{obj.name}": element {index} has no volume; left out')
                        continue
                    perturbations.append({
                        "shape": {"type": "quadric",
                                  "coefficients": [_round(c) for c in coefficients]},
                        "weight": _round(metaball.element_weight(el.stiffness, el.use_negative))})
            if not any(p["weight"] > 0 for p in perturbations):
                self.warn(f'metaball "{basis.name}": no positive element; nothing to render')
                continue
            self.shapes[family] = metaball.freeform(basis.data.threshold, perturbations)
            surface, medium = self.surface(basis, family)
            self.add_object(family, surface, medium)

    def volume(self, obj, matrix):
        data = obj.data
        where = f'volume "{obj.name}"'
        path = os.path.abspath(_blender_abspath(data.filepath))
        if not data.grids.load():
            # Blender could not read it either: no bounds to hold it, and nothing to render.
            message = data.grids.error_message or "cannot be read"
            raise ConversionError(f"{where}: {path}: {message}")
        corners = np.array([[float(c) for c in corner] for corner in obj.bound_box])
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        pad = 1e-3 * max(float(np.max(hi - lo)), 1e-6)
        steps, exact = _transform_steps(_matrix(matrix))
        if not exact:
            self.warn(f"{where}: its transform has shear, left out")
        medium, grid = self.volume_medium(obj, where, {g.name for g in data.grids})
        density = {"type": "vdb", "file": path, "grid": grid}
        if steps:
            density["transform"] = steps
        medium["density"] = density
        glow = medium.get("emission_per_length")
        if isinstance(glow, dict) and "grid" in glow:
            glow["file"] = path
            if steps:
                glow["transform"] = steps
        name = obj.name
        self.media[name] = medium
        shape = {"type": "box", "min": _vector(lo - pad), "max": _vector(hi + pad)}
        if steps:
            shape["transform"] = steps
        self.shapes[name] = shape
        self.add_object(name, {"type": "none"}, name)

    def volume_medium(self, obj, where, grids=None):
        """A Principled Volume's coefficients at unit grid density (Cycles' definitions):
        sigma_s = density colour, sigma_a = density (1 - colour)(1 - sqrt(absorption colour))."""
        material = obj.active_material
        node = None
        if material is not None and material.use_nodes and material.node_tree is not None:
            output = _active_output(material.node_tree, "OUTPUT_MATERIAL")
            node = _linked_node(output, "Volume") if output else None
        if node is None:
            # Blender's default for a volume object without a volume shader.
            return {"sigma_s": 1.0}, "density"
        if node.type != "PRINCIPLED_VOLUME":
            self.warn(f"{where}: a {node.name} node is not converted; the volume scatters white")
            return {"sigma_s": 1.0}, "density"
        mwhere = f'material "{material.name}"'
        color = self.input_value(node, "Color", mwhere)
        density = self.input_value(node, "Density", mwhere)
        absorption = self.input_value(node, "Absorption Color", mwhere)
        grid = node.inputs["Density Attribute"].default_value or "density"
        sigma_s = [density * max(color[i], 0.0) for i in range(3)]
        sigma_a = [density * max(1 - color[i], 0.0)
                   * max(1 - math.sqrt(max(absorption[i], 0.0)), 0.0) for i in range(3)]
        medium = {"sigma_a": [_round(c) for c in sigma_a], "sigma_s": [_round(c) for c in sigma_s]}
        g = self.input_value(node, "Anisotropy", mwhere)
        if g != 0:
            medium["phase"] = {"type": "hg", "g": _round(min(max(g, -0.99), 0.99))}
        emission = _rgb(self.input_value(node, "Emission Color", mwhere),
                        self.input_value(node, "Emission Strength", mwhere))
        # Cycles emits e per unit length, whatever the density: nimbus's emission_per_length.
        # Where the density is constant and the medium absorbs alike in every channel it is
        # nimbus's sigma_a L_e with L_e = e / sigma_a, which its trackers collect where paths are
        # absorbed: exactly the same light, with less noise in dense media (docs/blender.md).
        blackbody = self.blackbody(node, mwhere, grids)
        if blackbody is not None and any(e > 0 for e in emission):
            self.warn(f"{mwhere}: its emission colour left out: nimbus's medium emits one colour "
                      "per unit length, here the blackbody's")
        glow = blackbody if blackbody is not None else (
            [_round(e) for e in emission] if any(e > 0 for e in emission) else None)
        absorbs = grids is None and min(sigma_a) > 0
        if glow is None:
            pass
        elif isinstance(glow, list) and absorbs:
            medium["emission"] = [_round(emission[i] / sigma_a[i]) for i in range(3)]
        elif "blackbody" in glow and absorbs and max(sigma_a) - min(sigma_a) <= 1e-9 * max(sigma_a):
            medium["emission"] = {"blackbody": glow["blackbody"],
                                  "scale": _round(glow["scale"] / sigma_a[0])}
        else:
            medium["emission_per_length"] = glow
        return medium, grid

    def blackbody(self, node, where, grids):
        """A Principled Volume's blackbody emission per unit length, or None. Cycles emits a
        blackbody colour of luminance 10^-6 sigma_SB T^4 / pi at full intensity (sigma_SB the
        Stefan-Boltzmann constant), mixed with 1 by the intensity, at T = the Temperature input
        times the temperature grid where the volume has one: a {"blackbody": T} colour, or a
        temperature grid under the Stefan-Boltzmann law (its "file" and "transform" are the
        density's, which the caller adds)."""
        intensity = self.input_value(node, "Blackbody Intensity", where)
        if intensity <= 1e-3:
            return None
        tint = self.input_value(node, "Blackbody Tint", where)
        if any(abs(c - 1) > 1e-6 for c in tint[:3]):
            self.warn(f"{where}: the blackbody tint left out")
        kelvin = self.input_value(node, "Temperature", where)
        attribute = node.inputs["Temperature Attribute"].default_value
        if grids is not None and attribute in grids:
            # Cycles' (1 - intensity) share, 1.8e-14 per unit length, is left out.
            return {"grid": attribute, "law": "stefan-boltzmann",
                    "scale": _round(1e-6 * intensity), "temperature_scale": _round(kelvin)}
        if kelvin < 100:
            return None
        sigma = 5.670374419e-8 * 1e-6 / math.pi
        return {"blackbody": _round(kelvin),
                "scale": _round(sigma * ((1 - intensity) + intensity * kelvin ** 4))}

    def add_object(self, shape, surface, medium):
        obj = {"shape": shape, "surface": surface}
        if medium is not None:
            obj["medium"] = medium
        self.objects.append(obj)

    def run(self):
        film = self.film()
        document = {"film": film, "camera": self.camera(film), "integrator": self.integrator(),
                    "spectrum": self.spectrum()}
        self.world()
        metaballs = []
        items = []
        for inst in self.depsgraph.object_instances:
            # A metaball family's basis is evaluated to a mesh: the original says what it is.
            obj = inst.object.original
            if inst.is_instance and obj.type == "META":
                continue   # a family's tessellation, as an instance of its basis
            name = obj.name if not inst.is_instance else \
                f"{inst.parent.name}/{obj.name}/{tuple(inst.persistent_id)}"
            items.append((name, obj.type, obj, inst.matrix_world.copy()))
        items.sort(key=lambda item: item[0])
        for name, kind, obj, matrix in items:
            if kind == "META":
                metaballs.append((obj, matrix))
            elif kind == "LIGHT":
                self.light(obj, matrix)
            elif kind == "VOLUME":
                self.volume(obj, matrix)
            elif kind in ("CAMERA", "EMPTY", "LIGHT_PROBE", "SPEAKER"):
                continue
            elif kind == "MESH":
                self.warn(f'object "{obj.name}": a mesh is left out (nimbus renders functions: '
                          "model it as a metaball)")
            else:
                self.warn(f'object "{obj.name}": a {kind.lower()} object is left out')
        self.metaballs(metaballs)
        document["lights"] = self.lights
        document["shapes"] = self.shapes
        document["media"] = self.media
        document["objects"] = self.objects
        if not self.objects and not self.lights:
            self.warn("the scene has nothing nimbus renders: no metaball, volume or light")
        return document, self.warnings


def scene_document(depsgraph, settings):
    """(document, warnings) for an evaluated depsgraph and the scene's nimbus settings."""
    return Converter(depsgraph, settings).run()


def _active_output(tree, kind):
    outputs = [n for n in tree.nodes if n.type == kind]
    for n in outputs:
        if getattr(n, "is_active_output", False) and n.target in ("ALL", "CYCLES"):
            return n
    return outputs[0] if outputs else None


def _linked_node(node, socket):
    s = node.inputs.get(socket)
    if s is None or not s.is_linked:
        return None
    return s.links[0].from_node


def _area(data):
    if data.shape == "SQUARE":
        return data.size * data.size
    if data.shape == "RECTANGLE":
        return data.size * data.size_y
    if data.shape == "DISK":
        return math.pi * (data.size / 2) ** 2
    return math.pi * data.size * data.size_y / 4


def _blender_abspath(path):
    import bpy
    return bpy.path.abspath(path)


def _transform_steps(m):
    """A 4x4 affine matrix as the scene format's steps (scale, rotate, translate) and whether they
    reproduce it (no shear)."""
    linear = m[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.linalg.det(linear) < 0:
        scale[0] = -scale[0]
    rotation = linear / scale
    steps = []
    if not np.allclose(scale, 1.0, rtol=0, atol=1e-12):
        steps.append({"scale": _vector(scale)})
    angle, axis = _axis_angle(rotation)
    if angle != 0:
        steps.append({"rotate": {"axis": _vector(axis), "degrees": _round(angle)}})
    if not np.allclose(m[:3, 3], 0.0, rtol=0, atol=0):
        steps.append({"translate": _vector(m[:3, 3])})
    exact = np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-6)
    return steps, exact


def _axis_angle(r):
    c = max(min((np.trace(r) - 1) / 2, 1.0), -1.0)
    angle = math.degrees(math.acos(c))
    if angle < 1e-9:
        return 0.0, [0.0, 0.0, 1.0]
    if 180 - angle < 1e-6:
        # The axis of a half turn: the column of r + I with the largest norm.
        s = r + np.eye(3)
        col = s[:, int(np.argmax(np.linalg.norm(s, axis=0)))]
        return 180.0, col / np.linalg.norm(col)
    axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return angle, axis / np.linalg.norm(axis)

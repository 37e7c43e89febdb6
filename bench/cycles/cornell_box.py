"""Builds the Cornell box of ../shared/scenes/cornell-box/SPEC.md in Blender and renders it with
Cycles on the CPU, with the settings of a fair comparison: no adaptive sampling, no denoising, no
clamping, box pixel filter of width 1, 16 bounces of every kind, a fixed thread count, linear
float EXR output. Prints "cycles render seconds: S" (the render alone, scene set-up excluded).

Usage: blender -b --factory-startup --python bench/cycles/cornell_box.py -- \
           --spp 256 --threads 2 --seed 1 --resolution 512 --out cornell-cycles.exr [--fog SS,SA,G] [--oidn]

--fog fills the box with a homogeneous grey medium (a cube just inside the walls whose material has only a
volume: Volume Scatter of density SS with Henyey-Greenstein anisotropy G, plus Volume Absorption of
density SA, per millimetre), as bench/cycles_fog_vs_candela.py builds the same fog for candela.
--oidn denoises the render with OpenImageDenoise, fed the albedo and normal passes (bench/denoise.py); it exits
with a message where this Blender is built without OpenImageDenoise (Debian 12's 3.4.1 is).
"""
import argparse
import sys
import time

import bpy

# SPEC.md: millimetres, y up, right-handed, camera looking along +z. Blender is z up: rotate by +90
# degrees about x, (x, y, z) -> (x, -z, y), which keeps the handedness.
def to_blender(p):
    x, y, z = p
    return (x, -z, y)


QUADS = {
    "floor": ("white", [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)]),
    "ceiling": ("white", [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)]),
    "back wall": ("white", [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)]),
    "right wall": ("green", [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)]),
    "left wall": ("red", [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)]),
    "short top": ("white", [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)]),
    "short 1": ("white", [(290, 0, 114), (290, 165, 114), (240, 165, 272), (240, 0, 272)]),
    "short 2": ("white", [(130, 0, 65), (130, 165, 65), (290, 165, 114), (290, 0, 114)]),
    "short 3": ("white", [(82, 0, 225), (82, 165, 225), (130, 165, 65), (130, 0, 65)]),
    "short 4": ("white", [(240, 0, 272), (240, 165, 272), (82, 165, 225), (82, 0, 225)]),
    "tall top": ("white", [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)]),
    "tall 1": ("white", [(423, 0, 247), (423, 330, 247), (472, 330, 406), (472, 0, 406)]),
    "tall 2": ("white", [(472, 0, 406), (472, 330, 406), (314, 330, 456), (314, 0, 456)]),
    "tall 3": ("white", [(314, 0, 456), (314, 330, 456), (265, 330, 296), (265, 0, 296)]),
    "tall 4": ("white", [(265, 0, 296), (265, 330, 296), (423, 330, 247), (423, 0, 247)]),
    "light": ("light", [(343, 548.7, 227), (343, 548.7, 332), (213, 548.7, 332), (213, 548.7, 227)]),
}
ALBEDO = {"white": (0.725, 0.71, 0.68), "red": (0.63, 0.065, 0.05), "green": (0.14, 0.45, 0.091)}
LIGHT_RADIANCE = (17.0, 12.0, 4.0)


def shader_material(name, node_type, inputs, output):
    """A material whose surface is one shader node with the given input values."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes.clear()
    shader = m.node_tree.nodes.new(node_type)
    for key, value in inputs.items():
        shader.inputs[key].default_value = value
    out = m.node_tree.nodes.new("ShaderNodeOutputMaterial")
    m.node_tree.links.new(shader.outputs[output], out.inputs["Surface"])
    return m


def diffuse_material(name, rgb):
    # Roughness 0: Lambertian, not Oren-Nayar.
    return shader_material(name, "ShaderNodeBsdfDiffuse", {"Color": (*rgb, 1.0), "Roughness": 0.0}, "BSDF")


def emission_material(name, radiance):
    peak = max(radiance)  # radiance = colour x strength
    return shader_material(name, "ShaderNodeEmission",
                           {"Color": (*[c / peak for c in radiance], 1.0), "Strength": peak}, "Emission")


def build_scene(resolution):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    materials = {name: diffuse_material(name, rgb) for name, rgb in ALBEDO.items()}
    materials["light"] = emission_material("light", LIGHT_RADIANCE)
    for name, (material, quad) in QUADS.items():
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata([to_blender(p) for p in quad], [], [(0, 1, 2, 3)])
        mesh.materials.append(materials[material])
        obj = bpy.data.objects.new(name, mesh)
        scene.collection.objects.link(obj)
    # Camera at (278, 273, -800) looking along +z with y up; 35 mm lens on a 25 mm square film.
    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = 35.0
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.sensor_width = 25.0
    cam_data.clip_start = 1.0
    cam_data.clip_end = 1e5
    cam = bpy.data.objects.new("camera", cam_data)
    cam.location = to_blender((278, 273, -800))
    # A Blender camera looks along its local -z with +y up: 90 degrees about x makes it look along
    # world +y with +z (SPEC's +y) up, then 180 degrees about z along world -y (SPEC's +z), with
    # image right along world -x (SPEC: +x is the image's left).
    cam.rotation_euler = (1.5707963267948966, 0.0, 3.141592653589793)
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x = r.resolution_y = resolution
    r.resolution_percentage = 100
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGB"
    r.use_compositing = False
    r.use_sequencer = False
    scene.view_settings.view_transform = "Standard"
    c = scene.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = 16
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = 16
    c.volume_bounces = c.transparent_max_bounces = 16
    c.caustics_reflective = c.caustics_refractive = True
    c.blur_glossy = 0.0
    return scene


def add_fog(scene, sigma_s, sigma_a, g):
    """The fog's box [1, 555] x [1, 547] x [1, 558] (SPEC coordinates), a volume-only material."""
    m = bpy.data.materials.new("fog")
    m.use_nodes = True
    m.cycles.homogeneous_volume = True
    nodes = m.node_tree.nodes
    nodes.clear()
    scatter = nodes.new("ShaderNodeVolumeScatter")
    scatter.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scatter.inputs["Density"].default_value = sigma_s
    scatter.inputs["Anisotropy"].default_value = g
    absorb = nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)  # absorbs density x (1 - colour)
    absorb.inputs["Density"].default_value = sigma_a
    add = nodes.new("ShaderNodeAddShader")
    out = nodes.new("ShaderNodeOutputMaterial")
    m.node_tree.links.new(scatter.outputs["Volume"], add.inputs[0])
    m.node_tree.links.new(absorb.outputs["Volume"], add.inputs[1])
    m.node_tree.links.new(add.outputs["Shader"], out.inputs["Volume"])
    lo, hi = (1, 1, 1), (555, 547, 558)
    corners = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    # Wound so that the normals point out of the box (Cycles tells inside from outside by them).
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    mesh = bpy.data.meshes.new("fog")
    mesh.from_pydata([to_blender(p) for p in corners], [], faces)
    mesh.materials.append(m)
    obj = bpy.data.objects.new("fog", mesh)
    scene.collection.objects.link(obj)


def add_oidn(scene):
    """Denoising of the final render by OpenImageDenoise, with the albedo and normal passes as its guides."""
    import _cycles
    if not _cycles.with_openimagedenoise:
        sys.exit("this Blender is built without OpenImageDenoise (_cycles.with_openimagedenoise is False)")
    c = scene.cycles
    c.use_denoising = True
    c.denoiser = "OPENIMAGEDENOISE"
    c.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    c.denoising_prefilter = "ACCURATE"
    scene.view_layers[0].cycles.use_denoising = True


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser()
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--resolution", type=int, default=512)
    p.add_argument("--out", required=True)
    p.add_argument("--fog", help="SIGMA_S,SIGMA_A,G: fill the box with homogeneous fog")
    p.add_argument("--oidn", action="store_true", help="denoise with OpenImageDenoise (albedo and normal passes)")
    a = p.parse_args(argv)
    scene = build_scene(a.resolution)
    if a.oidn:
        add_oidn(scene)
    if a.fog:
        add_fog(scene, *[float(v) for v in a.fog.split(",")])
    scene.cycles.samples = a.spp
    scene.cycles.seed = a.seed
    scene.render.threads_mode = "FIXED"
    scene.render.threads = a.threads
    scene.render.filepath = a.out
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f"cycles render seconds: {time.perf_counter() - start:.3f}", flush=True)


main()

// Builds a small scene in code (a chromatic cloud in a sphere under a sun and a sky), renders it
// in two halves of its samples into one film, then again as a render job that saves a checkpoint
// at 4 samples per pixel and a second job that continues it to 8 (the same bits), and writes the
// image to the path given as the one argument (.png or .exr).

#include <nimbus/nimbus.h>

#include <cstdio>
#include <exception>
#include <filesystem>

int main(int argc, char** argv) {
  using namespace nimbus;
  if (argc != 2) {
    std::fprintf(stderr, "usage: embed OUT.png\n");
    return 2;
  }
  try {
    check_output_path(argv[1]);
    Scene scene;
    scene.settings.width = 64;
    scene.settings.height = 48;
    scene.settings.spp = 8;
    scene.camera = perspective_camera({0, 0.4, 3.2}, {0, 0, 0}, {0, 1, 0}, 45, 64, 48);

    Light sky;
    sky.type = Light::Type::Environment;
    sky.emission = Rgb({0.25, 0.3, 0.4});
    Light sun;
    sun.type = Light::Type::Directional;
    sun.direction = normalize(Vec3{-0.5, -1, -0.4});
    sun.emission = Rgb(3.0);
    scene.lights = {sky, sun};

    Medium cloud;
    cloud.sigma_s = Rgb({6.0, 9.0, 12.0});
    cloud.sigma_a = Rgb(0.1);
    cloud.g = 0.5;
    cloud.density = make_cloud_density(CloudParams{});
    scene.media.push_back(cloud);

    SceneObject ball;
    ball.tape = compile(*make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
    ball.bounds = compute_bounds(ball.tape).box;
    ball.surface.type = Surface::Type::None;  // index-matched: the medium is a field
    ball.medium = 0;
    scene.objects.push_back(ball);
    finish_scene(scene);

    // Samples [0, 4) and then [4, 8): the same bits as all 8 at once.
    Film film(scene.settings.width, scene.settings.height);
    RenderOptions options;
    options.range.s1 = 4;
    render_into(scene, film, options);
    options.range = {0, 0, -1, -1, 4, 8};
    const RenderStats stats = render_into(scene, film, options);

    // The render job: checkpoints, resuming, progress and cancellation. A scene built in code
    // names what identifies it, which a checkpoint must match to be continued.
    const nlohmann::json identity = {{"example", "embed"}, {"version", 1}};
    const std::string checkpoint = std::string(argv[1]) + ".nck";
    RenderJobOptions first;
    first.spp = 4;
    first.checkpoint = checkpoint;
    RenderJob start(first);
    start.set_scene(scene, identity);
    start.run();
    RenderJobOptions second;
    second.spp = 8;
    second.resume = checkpoint;
    RenderJob resume(second);
    resume.set_scene(scene, identity);
    const JobOutcome resumed = resume.run();
    std::filesystem::remove(checkpoint);
    if (!(resumed.film.sum == film.sum)) throw std::runtime_error("the resumed render differs");
    write_image(argv[1], to_image(resumed.film));
    const MeanEstimate m = image_mean(film);
    std::printf("embed: %s, image mean %.4f %.4f %.4f, %.3f s on %d threads; resumed: %s\n",
                argv[1], m.mean[0], m.mean[1], m.mean[2], stats.seconds, stats.threads,
                resume.summary(resumed).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "embed: %s\n", e.what());
    return 1;
  }
  return 0;
}

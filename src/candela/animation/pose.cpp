#include "candela/animation/pose.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace candela {

FrameTime frame_time(int frame, double fps, double shutter) {
  const double t = double(frame) / fps, half = 0.5 * shutter / fps;
  return {float(t - half), float(t + half)};
}

bool is_animated(const SceneDesc& desc) {
  return !desc.animation.empty() || desc.camera.fov_keys || desc.camera.focus_distance_keys ||
         desc.camera.lens_radius_keys;
}

namespace {

// A node's world transform at time t times `local`, or a SceneError naming `what`.
Transform placed(const SceneAnimation& animation, int node, const Transform& local, float t, const std::string& what) {
  const std::optional<Transform> world = Transform::from_matrix(animation.world_matrix(node, t));
  if (!world) throw SceneError(fmt::format("{}: its animated transform is singular at time {}", what, t));
  return *world * local;
}

// Where a shape that moves by its own two transforms (over the original transform times) is at t:
// held at its first transform before them and its last after them.
Transform held_in_motion(const Transform& start, const Transform& end, float start_time, float end_time, float t,
                         const std::string& what) {
  const float s = end_time > start_time ? std::clamp((t - start_time) / (end_time - start_time), 0.0f, 1.0f) : 0.0f;
  const std::optional<Transform> at = interpolate_transform(start, end, s);
  if (!at) throw SceneError(fmt::format("{}: its motion's transform is singular at time {}", what, t));
  return *at;
}

// The placement of a shape or instance over the frame: `to_world` (+ `to_world_end` where it moves).
template <typename Placed>
void pose_placement(const SceneDesc& animated, Placed& p, FrameTime time, const std::string& what) {
  const SceneAnimation& animation = animated.animation;
  if (p.animation_node >= 0) {
    const Transform local = p.to_world;
    p.to_world = placed(animation, p.animation_node, local, time.open, what);
    p.to_world_end.reset();
    if (animation.node_moves(p.animation_node) && time.close > time.open) {
      Transform end = placed(animation, p.animation_node, local, time.close, what);
      if (end != p.to_world) p.to_world_end = end;
    }
    p.animation_node = -1;
  } else if (p.to_world_end) {
    const Transform start = p.to_world, end = *p.to_world_end;
    const float t0 = animated.transform_start_time, t1 = animated.transform_end_time;
    p.to_world = held_in_motion(start, end, t0, t1, time.open, what);
    p.to_world_end.reset();
    Transform closing = held_in_motion(start, end, t0, t1, time.close, what);
    if (time.close > time.open && closing != p.to_world) p.to_world_end = closing;
  }
}

// A deforming mesh's vertices at the shutter's opening, and at its closing where they differ.
void pose_mesh(const SceneAnimation& animation, ShapeDesc& shape, FrameTime time) {
  auto* mesh = std::get_if<MeshShape>(&shape.geometry);
  if (!mesh) throw SceneError(fmt::format("{}: only triangle meshes deform", shape.name));
  const MeshDeformation& deformation = animation.deformations[size_t(shape.deformation)];
  const std::vector<Point3> rest_positions = mesh->mesh.positions;
  const std::vector<Normal3> rest_normals = mesh->mesh.normals;
  animation.deform(deformation, time.open, mesh->mesh.positions, mesh->mesh.normals);
  mesh->positions_end.clear();
  mesh->normals_end.clear();
  if (time.close > time.open) {
    std::vector<Point3> positions = rest_positions;
    std::vector<Normal3> normals = rest_normals;
    animation.deform(deformation, time.close, positions, normals);
    if (positions != mesh->mesh.positions) {
      mesh->positions_end = std::move(positions);
      mesh->normals_end = std::move(normals);
    }
  }
  shape.deformation = -1;
}

std::string shape_name(const ShapeDesc& shape, size_t index) {
  return shape.name.empty() ? fmt::format("shape {}", index) : fmt::format("shape \"{}\"", shape.name);
}

}  // namespace

SceneDesc pose_scene(const SceneDesc& animated, FrameTime time) {
  SceneDesc still = animated;
  still.animation = {};
  still.transform_start_time = time.open;
  still.transform_end_time = time.close;
  still.camera.shutter_open = time.open;
  still.camera.shutter_close = time.close;
  const SceneAnimation& animation = animated.animation;

  // The camera, and its lens, at the middle of the shutter interval.
  CameraDesc& camera = still.camera;
  const float middle = time.middle();
  if (camera.animation_node >= 0)
    camera.world_from_camera = placed(animation, camera.animation_node, camera.world_from_camera, middle, "the camera");
  camera.animation_node = -1;
  if (camera.fov_keys) camera.fov_degrees = camera.fov_keys->at(middle)[0];
  if (camera.focus_distance_keys) camera.focus_distance = camera.focus_distance_keys->at(middle)[0];
  if (camera.lens_radius_keys) camera.lens_radius = std::max(0.0f, camera.lens_radius_keys->at(middle)[0]);
  camera.fov_keys.reset();
  camera.focus_distance_keys.reset();
  camera.lens_radius_keys.reset();

  for (size_t i = 0; i < still.shapes.size(); ++i) {
    ShapeDesc& shape = still.shapes[i];
    if (shape.deformation >= 0) pose_mesh(animation, shape, time);
    pose_placement(animated, shape, time, shape_name(shape, i));
  }
  for (size_t i = 0; i < still.instances.size(); ++i)
    pose_placement(animated, still.instances[i], time, fmt::format("instance {}", i));
  return still;
}

}  // namespace candela

#pragma once
// The format-neutral scene description: plain structs with defaults that every reader (JSON, pbrt-v4,
// Mitsuba 3, glTF, OBJ) fills in and that scene/build turns into a render scene. Nothing after this
// point knows which file format a scene came from. Units are whatever the scene uses; colours are linear RGB.
// The description is the bottom layer (it needs only base/, math/ and animation/), split by domain: textures.h,
// materials.h, shapes.h, media.h, lights.h, camera_film.h, render_settings.h; this header holds the
// whole scene.
#include <string>
#include <vector>

#include "candela/animation/keyframes.h"
#include "candela/base/error.h"
#include "candela/description/camera_film.h"
#include "candela/description/lights.h"
#include "candela/description/materials.h"
#include "candela/description/media.h"
#include "candela/description/render_settings.h"
#include "candela/description/shapes.h"
#include "candela/description/textures.h"

namespace candela {

struct SceneDesc {
  CameraDesc camera;
  FilmDesc film;
  RenderSettings settings;
  std::vector<TextureDesc> textures;
  std::vector<MaterialDesc> materials;
  std::vector<ShapeDesc> shapes;
  std::vector<ObjectDesc> objects;
  std::vector<InstanceDesc> instances;
  std::vector<LightDesc> lights;
  std::vector<MediumDesc> media;  // referred to by shapes' interior/exterior and the camera
  // The times at which ShapeDesc::to_world and to_world_end hold (pbrt's TransformTimes).
  float transform_start_time = 0, transform_end_time = 1;
  // What moves over time (keyframes, skins, morph targets): animation/pose.h turns it into the
  // still scene of one frame, whose moving parts go from transform_start_time to transform_end_time.
  SceneAnimation animation;
  std::string source_file;  // the file it was read from, for messages and image metadata
  // Where the scene file declares each texture, material and light (parallel to those vectors;
  // shorter, or an empty file, where a reader does not know): errors found while building the
  // render scene name that place.
  struct Places {
    std::vector<SourceLocation> textures, materials, lights;
  } places;
};

}  // namespace candela

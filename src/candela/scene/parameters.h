#pragma once
// The editable parameters of a scene description by name (Mitsuba's traverse()): the camera's pose
// and lens, the constant (untextured) inputs of materials, lights' intensities, area emission and
// shape and instance transforms, and media's coefficients. The Python module lists, reads and changes them between renders
// without reading the scene's files again. Names:
//   camera.to_world, camera.fov, camera.lens_radius, camera.focus_distance
//   materials.<name>.<input>       e.g. materials.red.reflectance, materials.glass.roughness
//                                  (materials' and lights' numbers and colours come from their schemas,
//                                  description/schema.h)
//   lights.<index>.<key>           e.g. lights.0.intensity, lights.1.scale, lights.1.to_world
//   shapes.<name>.to_world, shapes.<name>.emission
//   instances.<index>.to_world
//   media.<name>.sigma_t, .albedo (a constant one), .scale, .emission, .g
// <name> is the material's name in the scene file (a JSON key, an OBJ newmtl) or the shape's name,
// else its index; where two share a name, both go by their index.
#include <string>
#include <variant>
#include <vector>

#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/description/scene_desc.h"

namespace candela {

using ParameterValue = std::variant<float, RGB, Matrix4>;

struct SceneParameter {
  std::string name;
  ParameterValue value;  // its current value (its kind: a number, a colour or a 4x4 matrix)
  std::string range;     // what it accepts, e.g. "0 < fov < 180", "each component >= 0"
};

// Every editable parameter of `scene`, in a stable order (camera, materials, lights, shapes, instances,
// media).
std::vector<SceneParameter> scene_parameters(const SceneDesc& scene);

// The named parameter's value. Throws UnknownParameterError for an unknown name (with the closest names).
ParameterValue scene_parameter(const SceneDesc& scene, const std::string& name);

// Sets the named parameter. Throws UnknownParameterError for an unknown name (with the closest
// names), UsageError for a value of the wrong kind or outside its range, which leaves the scene
// unchanged.
void set_scene_parameter(SceneDesc& scene, const std::string& name, const ParameterValue& value);

}  // namespace candela

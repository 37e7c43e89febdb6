#pragma once
// One frame of an animated scene: the description's animation (SceneDesc::animation) evaluated over
// the frame's shutter interval, giving a still scene whose moving parts go from their place at the
// shutter's opening to their place at its closing (motion blur within the frame).
#include "candela/description/scene_desc.h"

namespace candela {

// The shutter interval of one frame, in the scene's time (seconds for glTF and candela's keyframes).
struct FrameTime {
  float open = 0, close = 0;
  float middle() const { return 0.5f * (open + close); }
};

// Frame `frame` at `fps` frames per second: the frame's time is frame / fps, and the shutter is open
// for `shutter` of a frame's duration centred on it (Blender's default: centred, half a frame).
FrameTime frame_time(int frame, double fps, double shutter);

// The still scene at `time`: every animated shape, instance and mesh placed at time.open, and where
// it moves before time.close, placed there too as its end transform (or end vertices); the camera
// (which has no motion blur of its own) and its lens at the middle of the interval. Shapes that move
// by their own two transforms (to_world_end over the scene's transform times) keep moving so, held
// at their first or last transform outside those times. The result has no animation left.
// Throws SceneError where a transform becomes singular.
SceneDesc pose_scene(const SceneDesc& animated, FrameTime time);

// Whether the description has anything that changes between frames.
bool is_animated(const SceneDesc& desc);

}  // namespace candela

#pragma once
// A simulated capture scene: one or more subjects of one kind in a textured room.

#include <memory>
#include <string>
#include <vector>

#include "sim/scene/environment.h"
#include "sim/scene/subject.h"

namespace silnet::sim {

// The kinds of subject the simulator can stage.
enum class SubjectKind {
  kHuman,         // walking, turning, arm-raising figures
  kQuadruped,     // trotting four-legged animals
  kStatue,        // one static human figure in stone, for multi-view stereo
  kStillsStatue,  // the stereo stills' figure: a through-hole, a staff, T-junctions
                  // (stills_statue.h)
};

// Parses "human", "quadruped", "statue" or "stills-statue"; throws InputError otherwise.
SubjectKind ParseSubjectKind(const std::string& name);
std::string ToString(SubjectKind kind);

// Parameters of a scene.
struct SceneOptions {
  SubjectKind subject = SubjectKind::kHuman;
  int count = 1;             // subjects (ignored for both statues: always one)
  double walk_radius = 1.8;  // metres; subjects stay within this distance of the centre
  double mean_speed = 0.9;   // metres per second
  double time_begin = 0.0;   // seconds; motion is defined on [time_begin, time_end]
  double time_end = 30.0;
  bool lighting_changes = true;
  uint64_t seed = 1;
};

// Subjects and room; answers "what is where" at any reference time.
class Scene {
 public:
  explicit Scene(const SceneOptions& options);
  ~Scene();
  Scene(Scene&&) noexcept;

  // All subjects' primitives at reference time `time` (seconds), world frame.
  std::vector<Primitive> PrimitivesAt(double time) const;
  const std::vector<Material>& materials() const { return materials_; }
  const Environment& environment() const { return environment_; }
  int subject_count() const { return static_cast<int>(subjects_.size()); }
  const Subject& subject(int index) const { return *subjects_[static_cast<size_t>(index)]; }
  bool is_static() const {
    return options_.subject == SubjectKind::kStatue ||
           options_.subject == SubjectKind::kStillsStatue;
  }
  const SceneOptions& options() const { return options_; }

 private:
  SceneOptions options_;
  Environment environment_;
  std::vector<Material> materials_;
  std::vector<std::unique_ptr<Subject>> subjects_;
};

}  // namespace silnet::sim

// Native per-substep contact reading for fsvla's safety monitor.
//
// SAPIEN 3's CPU system keeps each touching shape pair's latest PhysX report in a map
// (sapien/physx/simulation_callback.hpp). From Python every report is a new object and
// every contact point three numpy arrays: 3-7 us a kept contact, 25 substeps a control
// step. This file reads that map directly and folds what the monitor keeps (see
// fsvla/monitor/native.py, which builds it against the headers SAPIEN's wheel ships and
// falls back to the Python reader when it cannot):
//
// - free bodies: net contact force and torque from the velocity change over a substep
//   (the formulas of fsvla.monitor.probe._FreeBody);
// - per component pair: the summed impulse of the pair's contacts and its moments about
//   each side's mass centre, for the pairs a filter keeps, folded into running maxima
//   (fsvla.monitor.probe.Probe._scan) or handed back as they are (Probe._read_last).
//
// Pointers cross the boundary as integers: the Python side gets them from pybind11's
// cross-module conduit (_pybind11_conduit_v1_), keyed by the type names below.

#include <sapien/physx/physx_system.h>
#include <sapien/physx/rigid_component.h>
#include <sapien/entity.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <typeinfo>
#include <unordered_map>
#include <vector>

using sapien::physx::Contact;
using sapien::physx::PhysxRigidBaseComponent;
using sapien::physx::PhysxSystemCpu;

namespace {

// A std::type_info carrying a mangled name: pybind11 looks registered types up by name,
// so this matches SAPIEN's own without linking against its module.
struct NamedType : std::type_info {
  explicit NamedType(const char *name) : std::type_info(name) {}
};
const NamedType kSystemType("N6sapien5physx14PhysxSystemCpuE");
const NamedType kComponentType("N6sapien5physx23PhysxRigidBaseComponentE");

enum Flags : uint32_t {
  kAnyPair = 1,     // every contact of the frame counts (not a robot's own links)
  kRobotPairs = 2,  // its contacts with a robot link count
  kTorque = 4,      // the torque about its mass centre is wanted
  kRobotLink = 8,   // a link of robot `robot`
};

struct Entry {
  uint32_t flags = 0;
  int32_t robot = -1;
};

struct Vec {
  double x = 0, y = 0, z = 0;
  double norm() const { return std::sqrt(x * x + y * y + z * z); }
};

struct PairSum {  // one substep's contacts of a component pair, a < b by address
  const void *a, *b;
  Vec impulse;             // on a, by b
  Vec moment_a, moment_b;  // of the impulses on a (on b) about a's (b's) mass centre
};

struct PairMax {  // since the last take; -1 where nothing was folded in
  const void *a, *b;
  double force = -1, torque_a = -1, torque_b = -1;
};

struct FreeBody {
  PhysxRigidBaseComponent *component;
  bool torque;
  double mass, inertia[3], cmass_q[4], weight[3];
  Vec v, w;  // last readings: linear velocity (world), angular (principal frame)
  double force = -1, torque_value = -1;
};

struct Reader {
  PhysxSystemCpu *system;
  std::unordered_map<const void *, Entry> entries;
  std::vector<FreeBody> free;
  std::vector<PairSum> sums;
  std::vector<PairMax> maxima;
};

const Entry *find(const Reader &r, const void *c) {
  auto it = r.entries.find(c);
  return it == r.entries.end() ? nullptr : &it->second;
}

bool wants(const Entry *e0, const Entry *e1) {
  bool any0 = e0 && (e0->flags & kAnyPair), any1 = e1 && (e1->flags & kAnyPair);
  if (any0 || any1) {
    int r0 = e0 ? e0->robot : -1, r1 = e1 ? e1->robot : -1;
    return r0 < 0 || r0 != r1;
  }
  bool link0 = e0 && (e0->flags & kRobotLink), link1 = e1 && (e1->flags & kRobotLink);
  return (e0 && (e0->flags & kRobotPairs) && link1) || (e1 && (e1->flags & kRobotPairs) && link0);
}

// Mass centre (world) of a rigid body; a static body's pose origin. In SAPIEN's pose
// arithmetic, as the Python reader's entity_pose * cmass_local_pose computes it.
Vec mass_centre(const void *component) {
  auto *actor = static_cast<const PhysxRigidBaseComponent *>(component)->getPxActor();
  sapien::Pose pose = sapien::PxTransformToPose(actor->getGlobalPose());
  if (auto *body = actor->is<::physx::PxRigidBody>()) {
    pose = pose * sapien::PxTransformToPose(body->getCMassLocalPose());
  }
  return {pose.p.x, pose.p.y, pose.p.z};
}

void add_moment(Vec &m, const Vec &centre, const sapien::Vec3 &p, double sign, const sapien::Vec3 &j) {
  double rx = p.x - centre.x, ry = p.y - centre.y, rz = p.z - centre.z;
  double ix = sign * j.x, iy = sign * j.y, iz = sign * j.z;
  m.x += ry * iz - rz * iy;
  m.y += rz * ix - rx * iz;
  m.z += rx * iy - ry * ix;
}

// Sum the kept contacts of the current reports per component pair into r.sums.
void sum_pairs(Reader &r, bool moments) {
  r.sums.clear();
  std::vector<std::pair<const void *, Vec>> centres;
  auto centre_of = [&](const void *c) -> const Vec & {
    for (auto &kv : centres) {
      if (kv.first == c) return kv.second;
    }
    centres.emplace_back(c, mass_centre(c));
    return centres.back().second;
  };
  for (const Contact *contact : r.system->getContacts()) {
    const void *c0 = contact->components[0], *c1 = contact->components[1];
    const Entry *e0 = find(r, c0), *e1 = find(r, c1);
    if ((!e0 && !e1) || !wants(e0, e1)) continue;
    bool first = c0 < c1;  // the impulses act on c0
    const void *a = first ? c0 : c1, *b = first ? c1 : c0;
    double sign = first ? 1.0 : -1.0;
    PairSum *sum = nullptr;
    for (auto &s : r.sums) {
      if (s.a == a && s.b == b) sum = &s;
    }
    if (!sum) {
      r.sums.push_back({a, b, {}, {}, {}});
      sum = &r.sums.back();
    }
    const Entry *ea = first ? e0 : e1, *eb = first ? e1 : e0;
    bool torque_a = moments && ea && (ea->flags & kTorque), torque_b = moments && eb && (eb->flags & kTorque);
    for (auto const &p : contact->points) {
      sum->impulse.x += sign * p.impulse.x;
      sum->impulse.y += sign * p.impulse.y;
      sum->impulse.z += sign * p.impulse.z;
      if (torque_a) add_moment(sum->moment_a, centre_of(a), p.position, sign, p.impulse);
      if (torque_b) add_moment(sum->moment_b, centre_of(b), p.position, -sign, p.impulse);
    }
  }
}

// A pair's maxima keep positive values only (a pair with no force was not touching);
// a free body's keep every reading (its net force is recorded every substep).
void keep_max(double &slot, double value) {
  if (value > 0.0 && value > slot) slot = value;
}

void keep_at_least(double &slot, double value) {
  if (value > slot) slot = value;
}

// Angular velocity in the principal frame: R^T w for R = pose.q * cmass_q.
Vec principal_omega(const FreeBody &f) {
  auto *actor = static_cast<::physx::PxRigidBody *>(f.component->getPxActor());
  ::physx::PxQuat q1 = actor->getGlobalPose().q;
  double a1 = q1.w, b1 = q1.x, c1 = q1.y, d1 = q1.z;
  double a2 = f.cmass_q[0], b2 = f.cmass_q[1], c2 = f.cmass_q[2], d2 = f.cmass_q[3];
  double w = a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2;
  double x = a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2;
  double y = a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2;
  double z = a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2;
  ::physx::PxVec3 o = actor->getAngularVelocity();
  double ox = o.x, oy = o.y, oz = o.z;
  return {(1 - 2 * (y * y + z * z)) * ox + 2 * (x * y + w * z) * oy + 2 * (x * z - w * y) * oz,
          2 * (x * y - w * z) * ox + (1 - 2 * (x * x + z * z)) * oy + 2 * (y * z + w * x) * oz,
          2 * (x * z + w * y) * ox + 2 * (y * z - w * x) * oy + (1 - 2 * (x * x + y * y)) * oz};
}

Vec linear_velocity(const FreeBody &f) {
  ::physx::PxVec3 v = static_cast<::physx::PxRigidBody *>(f.component->getPxActor())->getLinearVelocity();
  return {v.x, v.y, v.z};
}

void record_free(FreeBody &f, double inv_dt) {
  Vec v = linear_velocity(f);
  double m = f.mass * inv_dt;
  Vec force{m * (v.x - f.v.x) - f.weight[0], m * (v.y - f.v.y) - f.weight[1], m * (v.z - f.v.z) - f.weight[2]};
  f.v = v;
  keep_at_least(f.force, force.norm());
  if (!f.torque) return;
  Vec w = principal_omega(f);
  double ix = f.inertia[0], iy = f.inertia[1], iz = f.inertia[2];
  double lx = ix * w.x, ly = iy * w.y, lz = iz * w.z;
  Vec t{ix * (w.x - f.w.x) * inv_dt + w.y * lz - w.z * ly, iy * (w.y - f.w.y) * inv_dt + w.z * lx - w.x * lz,
        iz * (w.z - f.w.z) * inv_dt + w.x * ly - w.y * lx};
  f.w = w;
  keep_at_least(f.torque_value, t.norm());
}

}  // namespace

extern "C" {

// The type_info objects the Python side hands to the conduit.
const void *fsvla_system_type() { return static_cast<const std::type_info *>(&kSystemType); }
const void *fsvla_component_type() { return static_cast<const std::type_info *>(&kComponentType); }

// Layout facts the Python side checks against what it reads through SAPIEN's bindings.
int64_t fsvla_contact_count(void *system) {
  return static_cast<int64_t>(static_cast<PhysxSystemCpu *>(system)->getContacts().size());
}

void *fsvla_reader_new(void *system) { return new Reader{static_cast<PhysxSystemCpu *>(system), {}, {}, {}, {}}; }
void fsvla_reader_free(void *reader) { delete static_cast<Reader *>(reader); }

void fsvla_reader_set(void *reader, const void *component, uint32_t flags, int32_t robot) {
  static_cast<Reader *>(reader)->entries[component] = {flags, robot};
}

// A free body whose velocity-based net force (and torque) is folded every substep.
void fsvla_reader_add_free(void *reader, void *component, int32_t torque, double mass, const double *inertia,
                           const double *cmass_q, const double *gravity) {
  auto *r = static_cast<Reader *>(reader);
  FreeBody f{static_cast<PhysxRigidBaseComponent *>(component), torque != 0, mass, {}, {}, {}, {}, {}};
  for (int i = 0; i < 3; ++i) {
    f.inertia[i] = inertia[i];
    f.weight[i] = mass * gravity[i];
  }
  for (int i = 0; i < 4; ++i) f.cmass_q[i] = cmass_q[i];
  r->free.push_back(f);
}

// Re-read the free bodies' velocities and forget every maximum (an episode starts).
void fsvla_reader_reset(void *reader) {
  auto *r = static_cast<Reader *>(reader);
  r->maxima.clear();
  for (auto &f : r->free) {
    f.v = linear_velocity(f);
    if (f.torque) f.w = principal_omega(f);
    f.force = f.torque_value = -1;
  }
}

// Fold the substep just taken: free bodies (always), kept contact pairs (if scan).
void fsvla_reader_fold(void *reader, double inv_dt, int32_t scan) {
  auto *r = static_cast<Reader *>(reader);
  for (auto &f : r->free) record_free(f, inv_dt);
  if (!scan) return;
  sum_pairs(*r, true);
  for (auto const &s : r->sums) {
    PairMax *slot = nullptr;
    for (auto &m : r->maxima) {
      if (m.a == s.a && m.b == s.b) slot = &m;
    }
    if (!slot) {
      r->maxima.push_back({s.a, s.b});
      slot = &r->maxima.back();
    }
    keep_max(slot->force, s.impulse.norm() * inv_dt);
    keep_max(slot->torque_a, s.moment_a.norm() * inv_dt);
    keep_max(slot->torque_b, s.moment_b.norm() * inv_dt);
  }
}

// The free bodies' maxima since the last take, in the order they were added:
// rows of (force, torque), -1 where none; then forgets them if `clear`.
void fsvla_reader_take_free(void *reader, double *values, int32_t clear) {
  auto *r = static_cast<Reader *>(reader);
  for (size_t i = 0; i < r->free.size(); ++i) {
    values[2 * i] = r->free[i].force;
    values[2 * i + 1] = r->free[i].torque_value;
    if (clear) r->free[i].force = r->free[i].torque_value = -1;
  }
}

// The pair maxima since the last take: rows of (a, b) and (force, torque on a, torque on
// b), -1 where none; then forgets them if `clear`. Returns the row count; if over cap
// nothing is written or forgotten and minus the count is returned.
int64_t fsvla_reader_take(void *reader, uint64_t *pairs, double *values, int64_t cap, int32_t clear) {
  auto *r = static_cast<Reader *>(reader);
  int64_t n = static_cast<int64_t>(r->maxima.size());
  if (n > cap) return -n;
  for (int64_t i = 0; i < n; ++i) {
    auto const &m = r->maxima[i];
    pairs[2 * i] = reinterpret_cast<uint64_t>(m.a);
    pairs[2 * i + 1] = reinterpret_cast<uint64_t>(m.b);
    values[3 * i] = m.force;
    values[3 * i + 1] = m.torque_a;
    values[3 * i + 2] = m.torque_b;
  }
  if (clear) r->maxima.clear();
  return n;
}

// The kept pairs of the current reports: rows of (a, b) and the impulse on a by b.
// Returns the row count, or minus it when over cap (nothing written).
int64_t fsvla_reader_read(void *reader, uint64_t *pairs, double *impulses, int64_t cap) {
  auto *r = static_cast<Reader *>(reader);
  sum_pairs(*r, false);
  int64_t n = static_cast<int64_t>(r->sums.size());
  if (n > cap) return -n;
  for (int64_t i = 0; i < n; ++i) {
    auto const &s = r->sums[i];
    pairs[2 * i] = reinterpret_cast<uint64_t>(s.a);
    pairs[2 * i + 1] = reinterpret_cast<uint64_t>(s.b);
    impulses[3 * i] = s.impulse.x;
    impulses[3 * i + 1] = s.impulse.y;
    impulses[3 * i + 2] = s.impulse.z;
  }
  return n;
}

// World poses of n components as 4x4 row-major float32 matrices, as SAPIEN's
// Pose.to_transformation_matrix computes them (an entity's pose is its actor's).
void fsvla_poses(const uint64_t *components, int64_t n, float *out) {
  for (int64_t i = 0; i < n; ++i) {
    auto *component = reinterpret_cast<const PhysxRigidBaseComponent *>(components[i]);
    ::physx::PxTransform pose = component->getPxActor()->getGlobalPose();
    // normalized first, as SAPIEN does (Eigen, vectorised: the same roundings)
    Eigen::Matrix3f rotation =
        Eigen::Quaternionf(pose.q.w, pose.q.x, pose.q.y, pose.q.z).normalized().toRotationMatrix();
    float *m = out + 16 * i;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[4 * r + c] = rotation(r, c);
    }
    m[3] = pose.p.x;
    m[7] = pose.p.y;
    m[11] = pose.p.z;
    m[12] = m[13] = m[14] = 0.0f;
    m[15] = 1.0f;
  }
}

// One control step's reading in one call (Python's calls cost microseconds each right
// after PhysX stepped): the poses, the scan reader's free-body and pair maxima (then
// forgotten), and, if asked, the last reader's current pairs, into buffers the Python
// side owns and points to with fsvla_snapshot_buffers. counts gets the pair rows taken
// and the last pairs read; minus the count where a buffer was too small, and then that
// part is neither written nor forgotten (the Python side grows it and asks again).
struct Snapshot {
  Reader *scan = nullptr, *last = nullptr;
  std::vector<uint64_t> components;
  float *poses = nullptr;
  double *free_values = nullptr;
  uint64_t *pairs = nullptr, *last_pairs = nullptr;
  double *values = nullptr, *last_values = nullptr;
  int64_t cap = 0, last_cap = 0;
  int64_t *counts = nullptr;
};

void *fsvla_snapshot_new(void *scan, void *last, const uint64_t *components, int64_t n) {
  auto *s = new Snapshot;
  s->scan = static_cast<Reader *>(scan);
  s->last = static_cast<Reader *>(last);
  s->components.assign(components, components + n);
  return s;
}

void fsvla_snapshot_free(void *snapshot) { delete static_cast<Snapshot *>(snapshot); }

void fsvla_snapshot_buffers(void *snapshot, float *poses, double *free_values, uint64_t *pairs, double *values,
                            int64_t cap, uint64_t *last_pairs, double *last_values, int64_t last_cap,
                            int64_t *counts) {
  auto *s = static_cast<Snapshot *>(snapshot);
  s->poses = poses;
  s->free_values = free_values;
  s->pairs = pairs;
  s->values = values;
  s->cap = cap;
  s->last_pairs = last_pairs;
  s->last_values = last_values;
  s->last_cap = last_cap;
  s->counts = counts;
}

// The signature of a bound call (fsvla/monitor/native/bound.cpp); `unused` is not read.
void fsvla_snapshot_take(void *snapshot, double unused, int32_t read_last) {
  auto *s = static_cast<Snapshot *>(snapshot);
  fsvla_poses(s->components.data(), static_cast<int64_t>(s->components.size()), s->poses);
  fsvla_reader_take_free(s->scan, s->free_values, 1);
  s->counts[0] = fsvla_reader_take(s->scan, s->pairs, s->values, s->cap, 1);
  s->counts[1] = (read_last && s->last) ? fsvla_reader_read(s->last, s->last_pairs, s->last_values, s->last_cap) : 0;
}

// The name of a component's entity (for frames the monitor does not know), truncated to
// cap - 1 bytes; returns its full length.
int64_t fsvla_entity_name(const void *component, char *out, int64_t cap) {
  auto entity = static_cast<const PhysxRigidBaseComponent *>(component)->getEntity();
  std::string name = entity ? entity->getName() : std::string();
  if (cap > 0) {
    size_t n = std::min(name.size(), static_cast<size_t>(cap - 1));
    std::memcpy(out, name.data(), n);
    out[n] = '\0';
  }
  return static_cast<int64_t>(name.size());
}

}  // extern "C"

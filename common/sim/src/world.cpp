#include "nudge/sim/world.hpp"

#include "nudge/sim/mjcf.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/renderer.hpp"
#include "nudge/sim/sensor.hpp"

#include <mujoco/mujoco.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace nudge::sim {

namespace {

constexpr int kPusherGroup = 2;  // geom group of the pusher pad (hidden when !pusher_visible)
constexpr double kMaxGripperJump = 0.02;  // m: a larger move of the tool point snaps the hand
constexpr int kUnusedToolGroup = 3;  // the tool not in use: never drawn (mjv hides groups 3-5)

mjModel* compile(const std::string& xml, const std::string& source) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "nudge_world.xml";
  // Staged with its terminating NUL, whether the parser goes by the size or by the terminator.
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size() + 1)) != 0)
    throw SimError(source + ": cannot stage the model in MuJoCo's virtual file system");
  const int index = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[index], xml.c_str(), xml.size() + 1);
  char error[1000] = "";
  mjModel* model = mj_loadXML(name, vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  if (!model) throw SimError(source + ": MuJoCo rejected the generated model: " + error);
  return model;
}

Eigen::Vector3d vec3(const mjtNum* p) { return Eigen::Vector3d(p[0], p[1], p[2]); }

}  // namespace

double ObjectState::tilt() const {
  const Eigen::Vector3d z = orientation * Eigen::Vector3d::UnitZ();
  return std::acos(std::clamp(z.z(), -1.0, 1.0));
}

struct World::Impl {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::unique_ptr<Renderer> renderer;
  std::vector<int> body;        // object index -> body id
  std::vector<int> qpos_adr;    // object index -> address of its free joint in qpos
  std::vector<int> qvel_adr;
  std::vector<double> height;   // object index -> height
  std::vector<unsigned char> geom_label;  // geom id -> object index + 1, 0 for the rest
  int pusher_mocap = -1;
  int pad_geom = -1;
  std::vector<int> finger_geoms;     // the fingers' colliding faces
  std::vector<int> finger_visuals;   // the fingers' other geoms (stems)
  int finger_body[2] = {-1, -1};     // left, right
  int finger_qpos[2] = {-1, -1};     // their slide joints
  int hand_qpos = -1, hand_qvel = -1;  // the hand's free joint
  int finger_act[2] = {-1, -1};
  bool gripper = false;              // the tool in use: the gripper (else the pad)
  int camera_id[2] = {-1, -1};
  bool arm = false;                  // the scene has the PUMA 260
  int arm_qpos[6], arm_dof[6], arm_act[6];
  int flange_site = -1;
  bool tools_on_arm = false;         // the tools ride on the simulated flange
  double tool_length = robot::Workspace{}.tool_length;
  double tool_yaw = 0;
  // Puts the tool point on the simulated flange (kinematics as of the last mj_step1/mj_forward).
  void follow_flange() {
    const double* p = data->site_xpos + 3 * flange_site;
    const double* R = data->site_xmat + 9 * flange_site;  // row-major: column c = flange axis c
    const Eigen::Vector3d z(R[2], R[5], R[8]);
    const Eigen::Vector3d tool = Eigen::Vector3d(p[0], p[1], p[2]) + tool_length * z;
    const double horizontal = std::hypot(R[0], R[3]);  // the flange x axis' horizontal part
    if (horizontal > 1e-3) tool_yaw = std::atan2(R[3], R[0]);
    place_tool(tool, tool_yaw);
    if (!gripper) snap_hand();  // the gripper, not in use, rides along
  }
  std::mt19937_64 noise_rng;
  // Distortion warps, [0] for the rig's size, [1] for snapshots (built on first use).
  struct Warp {
    cv::Size size;          // the pinhole image rendered
    double fovy_deg = 0;    // its vertical field of view
    cv::Mat map_x, map_y;   // distorted pixel -> pinhole pixel
  };
  Warp warp[2];

  ~Impl() {
    renderer.reset();
    if (data) mj_deleteData(data);
    if (model) mj_deleteModel(model);
  }

  int object_of_geom(int geom) const {
    return geom >= 0 && geom < static_cast<int>(geom_label.size()) ? geom_label[geom] - 1 : -1;
  }
  bool is_tool_geom(int geom) const {
    return geom == pad_geom || std::find(finger_geoms.begin(), finger_geoms.end(), geom) != finger_geoms.end();
  }
  // Puts the hand exactly on the tool point, at rest (the weld then holds it there).
  void snap_hand() {
    const int k = pusher_mocap;
    for (int i = 0; i < 3; ++i) data->qpos[hand_qpos + i] = data->mocap_pos[3 * k + i];
    for (int i = 0; i < 4; ++i) data->qpos[hand_qpos + 3 + i] = data->mocap_quat[4 * k + i];
    for (int i = 0; i < 6; ++i) data->qvel[hand_qvel + i] = 0;
  }
  void place_tool(const Eigen::Vector3d& position, double yaw) {
    const int k = pusher_mocap;
    for (int i = 0; i < 3; ++i) data->mocap_pos[3 * k + i] = position[i];
    data->mocap_quat[4 * k + 0] = std::cos(0.5 * yaw);
    data->mocap_quat[4 * k + 1] = 0;
    data->mocap_quat[4 * k + 2] = 0;
    data->mocap_quat[4 * k + 3] = std::sin(0.5 * yaw);
  }
  // Collision bits and drawing group of the two tools for the one in use.
  void apply_tool() {
    auto set = [this](int g, int contype, int conaffinity, int group) {
      model->geom_contype[g] = contype;
      model->geom_conaffinity[g] = conaffinity;
      model->geom_group[g] = group;
    };
    set(pad_geom, gripper ? 0 : 2, gripper ? 0 : 2, gripper ? kUnusedToolGroup : kPusherGroup);
    for (int g : finger_geoms) set(g, gripper ? 2 : 0, 0, gripper ? kPusherGroup : kUnusedToolGroup);
    for (int g : finger_visuals) set(g, 0, 0, gripper ? kPusherGroup : kUnusedToolGroup);
  }
};

World::World(const Scene& input) : impl_(std::make_unique<Impl>()), scene_(input) {
  validate(scene_);
  // Seeded placement jitter: the only randomness in the physics, fixed by the scene's seed.
  std::mt19937_64 rng(scene_.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (size_t i = 0; i < scene_.objects.size(); ++i) {
    ObjectSpec& o = scene_.objects[i];
    if (o.name.empty()) o.name = o.kind + std::to_string(i);
    const double dx = normal(rng), dy = normal(rng), dyaw = normal(rng);
    o.position += scene_.physics.position_jitter * Eigen::Vector2d(dx, dy);
    o.yaw += scene_.physics.yaw_jitter * dyaw;
  }
  impl_->noise_rng.seed(scene_.seed ^ 0x9e3779b97f4a7c15ULL);
  rig_ = make_rig(scene_.rig);
  mjcf_ = build_mjcf(scene_);

  Impl& s = *impl_;
  s.model = compile(mjcf_, scene_.source);
  s.data = mj_makeData(s.model);
  if (!s.data) throw SimError(scene_.source + ": MuJoCo could not allocate mjData");
  s.geom_label.assign(s.model->ngeom, 0);
  for (size_t i = 0; i < scene_.objects.size(); ++i) {
    const std::string name = "obj" + std::to_string(i);
    const int b = mj_name2id(s.model, mjOBJ_BODY, name.c_str());
    const int j = mj_name2id(s.model, mjOBJ_JOINT, (name + "_joint").c_str());
    if (b < 0 || j < 0) throw SimError(scene_.source + ": generated model lacks " + name);
    s.body.push_back(b);
    s.qpos_adr.push_back(s.model->jnt_qposadr[j]);
    s.qvel_adr.push_back(s.model->jnt_dofadr[j]);
    s.height.push_back(model_of(scene_.objects[i], 8).height);
    for (int g = 0; g < s.model->ngeom; ++g)
      if (s.model->geom_bodyid[g] == b) s.geom_label[g] = static_cast<unsigned char>(i + 1);
  }
  const int pusher = mj_name2id(s.model, mjOBJ_BODY, "pusher");
  s.pusher_mocap = pusher >= 0 ? s.model->body_mocapid[pusher] : -1;
  s.pad_geom = mj_name2id(s.model, mjOBJ_GEOM, "pusher_pad");
  s.camera_id[0] = mj_name2id(s.model, mjOBJ_CAMERA, "left");
  s.camera_id[1] = mj_name2id(s.model, mjOBJ_CAMERA, "right");
  if (s.pusher_mocap < 0 || s.pad_geom < 0 || s.camera_id[0] < 0 || s.camera_id[1] < 0)
    throw SimError(scene_.source + ": generated model lacks the pusher or the cameras");
  if (s.model->geom_group[s.pad_geom] != kPusherGroup)
    throw SimError(scene_.source + ": the pusher pad is not in geom group 2");
  const int hand = mj_name2id(s.model, mjOBJ_BODY, "hand");
  const int hand_joint = mj_name2id(s.model, mjOBJ_JOINT, "hand_joint");
  if (hand < 0 || hand_joint < 0) throw SimError(scene_.source + ": generated model lacks the gripper's hand");
  s.hand_qpos = s.model->jnt_qposadr[hand_joint];
  s.hand_qvel = s.model->jnt_dofadr[hand_joint];
  std::vector<int> gripper_bodies{hand};
  const char* fingers[2] = {"finger_left", "finger_right"};
  for (int f = 0; f < 2; ++f) {
    const std::string name = fingers[f];
    const int b = mj_name2id(s.model, mjOBJ_BODY, name.c_str());
    const int j = mj_name2id(s.model, mjOBJ_JOINT, (name + "_slide").c_str());
    s.finger_act[f] = mj_name2id(s.model, mjOBJ_ACTUATOR, (name + "_act").c_str());
    if (b < 0 || j < 0 || s.finger_act[f] < 0)
      throw SimError(scene_.source + ": generated model lacks the gripper's " + name);
    s.finger_body[f] = b;
    s.finger_qpos[f] = s.model->jnt_qposadr[j];
    gripper_bodies.push_back(b);
  }
  for (int g = 0; g < s.model->ngeom; ++g)
    if (std::count(gripper_bodies.begin(), gripper_bodies.end(), s.model->geom_bodyid[g]))
      (s.model->geom_contype[g] ? s.finger_geoms : s.finger_visuals).push_back(g);
  s.apply_tool();
  // The gripper starts open.
  const double open = gripper_geometry().apex_for_opening(gripper_geometry().max_opening);
  for (int f = 0; f < 2; ++f) {
    s.data->ctrl[s.finger_act[f]] = open;
    s.data->qpos[s.finger_qpos[f]] = open;
  }

  if (scene_.arm.present) {
    for (int j = 0; j < 6; ++j) {
      const std::string n = std::to_string(j + 1);
      const int joint = mj_name2id(s.model, mjOBJ_JOINT, ("puma_j" + n).c_str());
      s.arm_act[j] = mj_name2id(s.model, mjOBJ_ACTUATOR, ("puma_act" + n).c_str());
      if (joint < 0 || s.arm_act[j] < 0) throw SimError(scene_.source + ": generated model lacks the arm's joint " + n);
      s.arm_qpos[j] = s.model->jnt_qposadr[joint];
      s.arm_dof[j] = s.model->jnt_dofadr[joint];
    }
    s.flange_site = mj_name2id(s.model, mjOBJ_SITE, "puma_flange");
    if (s.flange_site < 0) throw SimError(scene_.source + ": generated model lacks the arm's flange");
    s.arm = true;
    for (int j = 0; j < 6; ++j) s.data->qpos[s.arm_qpos[j]] = s.data->ctrl[s.arm_act[j]] = scene_.arm.joints[j];
  }

  mj_forward(s.model, s.data);
  step_for(scene_.physics.settle_time);
  s.data->time = 0;
}

World::~World() = default;

double World::time() const { return impl_->data->time; }
double World::timestep() const { return impl_->model->opt.timestep; }

void World::step(int n) {
  Impl& s = *impl_;
  if (!s.arm) {
    for (int i = 0; i < n; ++i) mj_step(s.model, s.data);
    return;
  }
  // The arm's gravity and Coriolis forces at this very state (mj_step1 computes them), applied
  // back as the servo's feed-forward before the accelerations: exact, and a function of the
  // state only, so a restored state replays bit for bit.
  for (int i = 0; i < n; ++i) {
    mj_step1(s.model, s.data);
    for (int j = 0; j < 6; ++j) s.data->qfrc_applied[s.arm_dof[j]] = s.data->qfrc_bias[s.arm_dof[j]];
    // The tools follow the flange as it is at this state (the mocap body moves in the next step's
    // kinematics: 2 ms behind the arm).
    if (s.tools_on_arm) s.follow_flange();
    mj_step2(s.model, s.data);
  }
}

void World::mount_tools_on_arm(double tool_length) {
  Impl& s = *impl_;
  if (!s.arm) throw SimError(scene_.source + ": the scene has no arm (arm: present)");
  if (!(tool_length >= 0 && tool_length <= 0.5)) throw std::invalid_argument("tool length must be in [0, 0.5] m");
  s.tools_on_arm = true;
  s.tool_length = tool_length;
  mj_kinematics(s.model, s.data);
  s.follow_flange();
  s.snap_hand();
  mj_kinematics(s.model, s.data);
}

bool World::tools_on_arm() const { return impl_->tools_on_arm; }

void World::set_gripper_opening(double opening) {
  if (!std::isfinite(opening)) throw std::invalid_argument("World::set_gripper_opening: opening must be finite");
  Impl& s = *impl_;
  if (!s.gripper) {
    use_gripper(true);
    s.snap_hand();
  }
  const GripperGeometry& g = gripper_geometry();
  const double apex = g.apex_for_opening(std::clamp(opening, 0.0, g.max_opening));
  for (int f = 0; f < 2; ++f) s.data->ctrl[s.finger_act[f]] = apex;
}

bool World::has_arm() const { return impl_->arm; }

void World::set_arm_targets(const std::array<double, 6>& joints) {
  Impl& s = *impl_;
  if (!s.arm) throw SimError(scene_.source + ": the scene has no arm (arm: present)");
  for (int j = 0; j < 6; ++j) {
    if (!std::isfinite(joints[j])) throw std::invalid_argument("arm joint " + std::to_string(j + 1) + " target is not finite");
    const double* range = s.model->actuator_ctrlrange + 2 * s.arm_act[j];
    s.data->ctrl[s.arm_act[j]] = std::clamp(joints[j], range[0], range[1]);
  }
}

std::array<double, 6> World::arm_targets() const {
  std::array<double, 6> q{};
  if (impl_->arm)
    for (int j = 0; j < 6; ++j) q[j] = impl_->data->ctrl[impl_->arm_act[j]];
  return q;
}

std::array<double, 6> World::arm_joints() const {
  std::array<double, 6> q{};
  if (impl_->arm)
    for (int j = 0; j < 6; ++j) q[j] = impl_->data->qpos[impl_->arm_qpos[j]];
  return q;
}

void World::set_arm_joints(const std::array<double, 6>& joints) {
  set_arm_targets(joints);
  Impl& s = *impl_;
  for (int j = 0; j < 6; ++j) {
    s.data->qpos[s.arm_qpos[j]] = s.data->ctrl[s.arm_act[j]];
    s.data->qvel[s.arm_dof[j]] = 0;
  }
  mj_kinematics(s.model, s.data);
}

Eigen::Isometry3d World::arm_flange_pose() const {
  const Impl& s = *impl_;
  if (!s.arm) throw SimError(scene_.source + ": the scene has no arm (arm: present)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    pose.translation()[r] = s.data->site_xpos[3 * s.flange_site + r];
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = s.data->site_xmat[9 * s.flange_site + 3 * r + c];
  }
  return pose;
}

void World::step_for(double seconds) {
  if (!(seconds >= 0)) throw std::invalid_argument("World::step_for: seconds must be >= 0");
  step(static_cast<int>(std::lround(seconds / timestep())));
}

std::vector<double> World::state() const {
  const mjModel* m = impl_->model;
  const mjData* d = impl_->data;
  std::vector<double> out;
  out.reserve(2 + m->nq + 2 * m->nv + 7 * m->nmocap + m->na + m->nu);
  out.push_back(d->time);
  out.insert(out.end(), d->qpos, d->qpos + m->nq);
  out.insert(out.end(), d->qvel, d->qvel + m->nv);
  out.insert(out.end(), d->mocap_pos, d->mocap_pos + 3 * m->nmocap);
  out.insert(out.end(), d->mocap_quat, d->mocap_quat + 4 * m->nmocap);
  out.insert(out.end(), d->act, d->act + m->na);
  // The constraint solver starts from the last accelerations: part of the state for exact replay.
  out.insert(out.end(), d->qacc_warmstart, d->qacc_warmstart + m->nv);
  out.insert(out.end(), d->ctrl, d->ctrl + m->nu);  // the fingers' commanded positions
  out.push_back(impl_->gripper ? 1.0 : 0.0);         // the tool in use
  return out;
}

void World::set_state(const std::vector<double>& state) {
  const mjModel* m = impl_->model;
  mjData* d = impl_->data;
  const size_t size = 2 + m->nq + 2 * m->nv + 7 * m->nmocap + m->na + m->nu;
  if (state.size() != size)
    throw std::invalid_argument("World::set_state: expected " + std::to_string(size) +
                                " values, got " + std::to_string(state.size()));
  for (double v : state)
    if (!std::isfinite(v)) throw std::invalid_argument("World::set_state: non-finite value");
  const double* p = state.data();
  d->time = *p++;
  const double* qpos = p;
  std::copy(p, p + m->nq, d->qpos);
  p += m->nq;
  std::copy(p, p + m->nv, d->qvel);
  p += m->nv;
  std::copy(p, p + 3 * m->nmocap, d->mocap_pos);
  p += 3 * m->nmocap;
  std::copy(p, p + 4 * m->nmocap, d->mocap_quat);
  p += 4 * m->nmocap;
  std::copy(p, p + m->na, d->act);
  p += m->na;
  const double* warmstart = p;
  p += m->nv;
  std::copy(p, p + m->nu, d->ctrl);
  p += m->nu;
  impl_->gripper = *p != 0;
  impl_->apply_tool();
  mj_forward(m, d);  // positions of bodies, contacts: for rendering and queries
  // mj_forward renormalises the free joints' quaternions in qpos in place, which can change their
  // last bits (and, through contacts, the whole future): put back the exact state.
  std::copy(qpos, qpos + m->nq, d->qpos);
  std::copy(warmstart, warmstart + m->nv, d->qacc_warmstart);
}

int World::object_index(const std::string& name) const {
  for (int i = 0; i < num_objects(); ++i)
    if (scene_.objects[i].name == name) return i;
  return -1;
}

ObjectState World::object(int index) const {
  if (index < 0 || index >= num_objects())
    throw std::out_of_range("World::object: no object " + std::to_string(index));
  const Impl& s = *impl_;
  const mjtNum* q = s.data->qpos + s.qpos_adr[index];
  const mjtNum* v = s.data->qvel + s.qvel_adr[index];
  ObjectState st;
  st.name = scene_.objects[index].name;
  st.kind = scene_.objects[index].kind;
  st.position = vec3(q);
  st.orientation = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized();
  st.linear_velocity = vec3(v);
  // A free joint's angular velocity is in the body frame.
  st.angular_velocity = st.orientation * vec3(v + 3);
  st.height = s.height[index];
  st.mass = s.model->body_mass[s.body[index]];
  // From the pose, so it is right even before the next mj_forward.
  st.centre_of_mass = st.position + st.orientation * vec3(s.model->body_ipos + 3 * s.body[index]);
  return st;
}

void World::set_object_pose(int index, const Eigen::Vector3d& position,
                            const Eigen::Quaterniond& orientation) {
  if (index < 0 || index >= num_objects())
    throw std::out_of_range("World::set_object_pose: no object " + std::to_string(index));
  if (!position.allFinite() || !orientation.coeffs().allFinite() || orientation.norm() < 1e-9)
    throw std::invalid_argument("World::set_object_pose: pose must be finite");
  Impl& s = *impl_;
  const Eigen::Quaterniond q = orientation.normalized();
  mjtNum* qpos = s.data->qpos + s.qpos_adr[index];
  for (int i = 0; i < 3; ++i) qpos[i] = position[i];
  qpos[3] = q.w();
  qpos[4] = q.x();
  qpos[5] = q.y();
  qpos[6] = q.z();
  for (int i = 0; i < 6; ++i) s.data->qvel[s.qvel_adr[index] + i] = 0;
  mj_forward(s.model, s.data);
}

void World::place_object(int index, const Eigen::Vector2d& xy, double yaw) {
  set_object_pose(index, Eigen::Vector3d(xy.x(), xy.y(), 0.0),
                  Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())));
}

Axis3d World::axis(int index) const {
  const ObjectState st = object(index);
  Axis3d a;
  a.base = st.position;
  a.direction = st.orientation * Eigen::Vector3d::UnitZ();
  a.height = st.height;
  return a;
}

ImageLine World::axis_in_image(int index, int camera_index) const {
  return project_axis(camera(camera_index), axis(index));
}

void World::set_pusher(const Eigen::Vector3d& position, double yaw) {
  if (!position.allFinite() || !std::isfinite(yaw))
    throw std::invalid_argument("World::set_pusher: position and yaw must be finite");
  use_gripper(false);
  impl_->place_tool(position, yaw);
  impl_->snap_hand();  // the gripper, not in use, rides along
}

void World::use_gripper(bool gripper) {
  if (impl_->gripper == gripper) return;
  impl_->gripper = gripper;
  impl_->apply_tool();
}

void World::set_end_effector(const Eigen::Vector3d& position, double yaw, double opening) {
  if (!position.allFinite() || !std::isfinite(yaw) || !std::isfinite(opening))
    throw std::invalid_argument("World::set_end_effector: position, yaw and opening must be finite");
  Impl& s = *impl_;
  // The hand follows the tool point through a soft weld; it is put there directly when the
  // gripper comes into use and after a jump (a new motion starting elsewhere).
  const double jump = (position - vec3(s.data->qpos + s.hand_qpos)).norm();
  const bool snap = !s.gripper || jump > kMaxGripperJump;
  use_gripper(true);
  s.place_tool(position, yaw);
  if (snap) s.snap_hand();
  const GripperGeometry& g = gripper_geometry();
  const double apex = g.apex_for_opening(std::clamp(opening, 0.0, g.max_opening));
  for (int f = 0; f < 2; ++f) s.data->ctrl[s.finger_act[f]] = apex;
}

void World::place_gripper(const Eigen::Vector3d& position, double yaw, double opening) {
  if (!position.allFinite() || !std::isfinite(yaw) || !std::isfinite(opening))
    throw std::invalid_argument("World::place_gripper: position, yaw and opening must be finite");
  Impl& s = *impl_;
  use_gripper(true);
  s.place_tool(position, yaw);
  s.snap_hand();
  const GripperGeometry& g = gripper_geometry();
  const double apex = g.apex_for_opening(std::clamp(opening, 0.0, g.max_opening));
  for (int f = 0; f < 2; ++f) {
    s.data->ctrl[s.finger_act[f]] = apex;
    s.data->qpos[s.finger_qpos[f]] = apex;
  }
}

bool World::gripper_in_use() const { return impl_->gripper; }

double World::gripper_opening() const {
  const mjtNum* q = impl_->data->qpos;
  return gripper_geometry().opening_for_apex(0.5 * (q[impl_->finger_qpos[0]] + q[impl_->finger_qpos[1]]));
}

double World::gripper_commanded_opening() const {
  const mjtNum* c = impl_->data->ctrl;
  return gripper_geometry().opening_for_apex(0.5 * (c[impl_->finger_act[0]] + c[impl_->finger_act[1]]));
}

bool World::gripper_holds(int index) const {
  if (index < 0 || index >= num_objects())
    throw std::out_of_range("World::gripper_holds: no object " + std::to_string(index));
  const Impl& s = *impl_;
  if (!s.gripper) return false;
  bool touched[2] = {false, false};
  for (int i = 0; i < s.data->ncon; ++i) {
    const mjContact& c = s.data->contact[i];
    for (const auto& [tool, other] : {std::pair(c.geom1, c.geom2), std::pair(c.geom2, c.geom1)}) {
      if (s.object_of_geom(other) != index) continue;
      for (int f = 0; f < 2; ++f)
        if (s.model->geom_bodyid[tool] == s.finger_body[f]) touched[f] = true;
    }
  }
  return touched[0] && touched[1];
}

void World::park_pusher() { set_pusher(pusher_park_position(), 0.0); }

Eigen::Vector3d World::pusher_position() const {
  return vec3(impl_->data->mocap_pos + 3 * impl_->pusher_mocap);
}

bool World::pusher_in_contact() const {
  const mjData* d = impl_->data;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (impl_->is_tool_geom(c.geom1) && impl_->object_of_geom(c.geom2) >= 0) return true;
    if (impl_->is_tool_geom(c.geom2) && impl_->object_of_geom(c.geom1) >= 0) return true;
  }
  return false;
}

PushResult World::push(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double speed,
                       double settle) {
  if (!from.allFinite() || !to.allFinite())
    throw std::invalid_argument("World::push: from and to must be finite");
  if (!(speed > 0 && speed <= 2.0))
    throw std::invalid_argument("World::push: speed must be in (0, 2] m/s");
  if (!(settle >= 0)) throw std::invalid_argument("World::push: settle must be >= 0");
  const Eigen::Vector3d delta = to - from;
  const double yaw = std::atan2(delta.y(), delta.x());
  PushResult result;
  result.start_time = time();
  set_pusher(from, yaw);
  mj_forward(impl_->model, impl_->data);
  if (pusher_in_contact()) {
    park_pusher();
    mj_forward(impl_->model, impl_->data);
    throw SimError("World::push: the pad already touches an object at the start point");
  }
  const int steps = std::max(1, static_cast<int>(std::ceil(delta.norm() / (speed * timestep()))));
  for (int pass = 0; pass < 2; ++pass) {  // out, then back
    for (int k = 1; k <= steps; ++k) {
      const double f = static_cast<double>(k) / steps;
      const Eigen::Vector3d p = pass == 0 ? Eigen::Vector3d(from + f * delta) : Eigen::Vector3d(to - f * delta);
      set_pusher(p, yaw);
      step();
      result.contact = result.contact || pusher_in_contact();
    }
  }
  park_pusher();
  step_for(settle);
  result.end_time = time();
  return result;
}

cv::Mat World::render(int camera_index) { return draw(camera_index, false, false); }

cv::Mat World::render_mask(int camera_index) { return draw(camera_index, false, true); }

cv::Mat World::render_snapshot(int camera_index) { return draw(camera_index, true, false); }

cv::Mat World::render_snapshot_mask(int camera_index) { return draw(camera_index, true, true); }

cv::Mat World::render_snapshot_tool_mask(int camera_index) {
  constexpr unsigned char kTool = 255;  // above every object's label (index + 1)
  Impl& s = *impl_;
  // The objects' labels and the pusher's visibility come back however draw() ends.
  struct Restore {
    std::vector<unsigned char>& labels;
    const std::vector<unsigned char> saved;
    bool& visible;
    const bool was;
    ~Restore() {
      labels = saved;
      visible = was;
    }
  } restore{s.geom_label, s.geom_label, pusher_visible, pusher_visible};
  for (int g = 0; g < s.model->ngeom; ++g) s.geom_label[g] = s.model->geom_group[g] == kPusherGroup ? kTool : 0;
  pusher_visible = true;
  return draw(camera_index, true, true) == kTool;
}

CameraModel World::snapshot_camera(int camera_index) const {
  return scaled(camera(camera_index), scene_.render.snapshot_scale);
}

cv::Mat World::render_surface(int camera_index, cv::Mat* mask) {
  cv::Mat surface;
  cv::Mat labels = draw(camera_index, false, true, &surface);
  if (mask) *mask = labels;
  return surface;
}

cv::Mat World::render_snapshot_surface(int camera_index, cv::Mat* mask) {
  cv::Mat surface;
  cv::Mat labels = draw(camera_index, true, true, &surface);
  if (mask) *mask = labels;
  return surface;
}

// Back-projects each labelled pixel of an ideal pinhole image (focal length and principal point of
// `cam`'s K, centred in the image drawn) to the world, then into its object's frame.
cv::Mat World::surface_points(const cv::Mat& labels, const cv::Mat& depth, const CameraModel& cam) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  cv::Mat points(labels.size(), CV_32FC3, cv::Scalar(nan, nan, nan));
  const double fx = cam.lens.K(0, 0), fy = cam.lens.K(1, 1);
  const double cx = 0.5 * (labels.cols - 1), cy = 0.5 * (labels.rows - 1);
  std::vector<Eigen::Isometry3d> world_to_object(num_objects());
  for (int i = 0; i < num_objects(); ++i) {
    const ObjectState o = object(i);
    world_to_object[i] = (Eigen::Translation3d(o.position) * o.orientation).inverse();
  }
  const Eigen::Matrix3d Rt = cam.R.transpose();
  for (int v = 0; v < labels.rows; ++v) {
    const unsigned char* label = labels.ptr<unsigned char>(v);
    const float* z = depth.ptr<float>(v);
    cv::Vec3f* out = points.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (label[u] == 0 || label[u] > num_objects()) continue;
      const Eigen::Vector3d in_camera(z[u] * (u - cx) / fx, z[u] * (v - cy) / fy, z[u]);
      const Eigen::Vector3d p = world_to_object[label[u] - 1] * (Rt * (in_camera - cam.t));
      out[u] = cv::Vec3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
  }
  return points;
}

cv::Mat World::draw(int camera_index, bool snapshot, bool labels, cv::Mat* surface) {
  if (camera_index < 0 || camera_index > 1)
    throw std::out_of_range("World::render: camera must be 0 (left) or 1 (right)");
  Impl& s = *impl_;
  if (!s.renderer)
    s.renderer = std::make_unique<Renderer>(s.model, s.model->vis.global.offwidth,
                                            s.model->vis.global.offheight);
  const CameraModel cam = snapshot ? snapshot_camera(camera_index) : camera(camera_index);
  const int id = s.camera_id[camera_index];
  const int hidden = pusher_visible ? -1 : kPusherGroup;

  // A distorted camera: render a larger ideal pinhole image with the same focal length, then
  // warp it. Both cameras share intrinsics, so one warp per image size serves both.
  Impl::Warp* warp = nullptr;
  if (cam.distorted()) {
    warp = &s.warp[snapshot ? 1 : 0];
    if (warp->map_x.empty()) {
      const PinholeCanvas canvas = pinhole_canvas(cam);
      warp->size = cv::Size(canvas.width, canvas.height);
      warp->map_x.create(cam.lens.height, cam.lens.width, CV_32F);
      warp->map_y.create(cam.lens.height, cam.lens.width, CV_32F);
      const double cx = 0.5 * (canvas.width - 1), cy = 0.5 * (canvas.height - 1);
      for (int v = 0; v < cam.lens.height; ++v)
        for (int u = 0; u < cam.lens.width; ++u) {
          const Eigen::Vector2d n = cam.undistort(Eigen::Vector2d(u, v));
          warp->map_x.at<float>(v, u) = static_cast<float>(cam.lens.K(0, 0) * n.x() + cx);
          warp->map_y.at<float>(v, u) = static_cast<float>(cam.lens.K(1, 1) * n.y() + cy);
        }
      warp->fovy_deg = 2 * std::atan(0.5 * canvas.height / cam.lens.K(1, 1)) * 180.0 / M_PI;
    }
  }
  const cv::Size size = warp ? warp->size : cv::Size(cam.lens.width, cam.lens.height);
  const mjtNum fovy = s.model->cam_fovy[id];
  if (warp) s.model->cam_fovy[id] = warp->fovy_deg;
  cv::Mat image;
  try {
    cv::Mat depth;
    image = labels ? s.renderer->labels(s.data, id, s.geom_label, hidden, size, surface ? &depth : nullptr)
                   : s.renderer->colour(s.data, id, scene_.render, hidden, size);
    if (surface) *surface = surface_points(image, depth, cam);
  } catch (...) {
    s.model->cam_fovy[id] = fovy;
    throw;
  }
  s.model->cam_fovy[id] = fovy;
  if (warp) {
    cv::Mat warped;
    cv::remap(image, warped, warp->map_x, warp->map_y,
              labels ? cv::INTER_NEAREST : cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    image = warped;
    if (surface) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      cv::Mat points;
      cv::remap(*surface, points, warp->map_x, warp->map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                cv::Scalar(nan, nan, nan));
      *surface = points;
    }
  }
  if (!labels) add_sensor_noise(image, scene_.render.noise_sigma, s.noise_rng);
  return image;
}

StereoImages World::render_stereo(bool masks) {
  StereoImages out;
  out.time = time();
  for (int c = 0; c < 2; ++c) {
    out.colour[c] = render(c);
    if (masks) out.mask[c] = render_mask(c);
  }
  return out;
}

}  // namespace nudge::sim

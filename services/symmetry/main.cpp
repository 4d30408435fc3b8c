// symmetry: detects bilateral symmetry lines in every image on its input channels and publishes
// them on the matching SYMMETRY_* channel (CAMERA_LEFT -> SYMMETRY_LEFT, CAMERA -> SYMMETRY); with
// --contours N also the object contours of the top N lines on CONTOURS_* (thesis sec. 4.2).
#include <cmath>

#include "handlers.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/flags.hpp"
#include "nudge/geometry/self_mask.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/robot/safety.hpp"

using namespace nudge;

namespace {

// A rig file's cameras, table and arm base, for the options that place things on the table; every
// input channel must name its camera. Throws std::invalid_argument naming what is missing.
struct RigOnTable {
  geometry::StereoRig rig;
  geometry::Plane table;
  Eigen::Vector3d arm_base;
};
RigOnTable rig_on_table(const std::string& path, const std::vector<std::string>& inputs) {
  const geometry::Workspace scene = geometry::load_workspace(path);
  if (!scene.table || !scene.arm_base) throw std::invalid_argument(path + " needs table_plane and arm_base");
  for (const auto& channel : inputs) symmetry_service::side_of_channel(channel);
  return {geometry::load_rig(path), *scene.table, *scene.arm_base};
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("symmetry", [&] {
    bus::Service service("symmetry", "Fast bilateral symmetry detection (thesis ch. 3) on camera images.");
    symmetry_service::Options options;
    symmetry::Params& params = options.params;
    symmetry::EdgeParams& edge = options.edge;
    edge.blur_sigma = 1.0;  // thesis: Gaussian blur first on camera images
    std::string inputs = std::string(bus::channel::CAMERA_LEFT) + "," + bus::channel::CAMERA_RIGHT;
    std::vector<double> canny = {edge.canny_low, edge.canny_high};
    auto& f = service.flags();
    f.add_string("inputs", &inputs, "comma-separated image channels");
    f.add_int("lines", &params.num_lines, "symmetry lines per image (Nlines)");
    f.add_double("dmin", &params.dmin, "minimum pairing distance, px");
    f.add_double("dmax", &params.dmax, "maximum pairing distance, px (0: none)");
    f.add_double("theta-min", &params.theta_min_deg, "orientation limit, degrees");
    f.add_double("theta-max", &params.theta_max_deg, "orientation limit, degrees");
    f.add_doubles("canny", &canny, 2, "Canny thresholds LOW HIGH");
    f.add_double("blur", &edge.blur_sigma, "Gaussian blur sigma before Canny (0: none)");
    f.add_double("min-peak-ratio", &params.min_peak_ratio, "drop peaks below this fraction of the top one");
    f.add_bool("once-per-row", &params.once_per_row, "a row of Rot increments a bin at most once");
    f.add_int("max-row-pixels", &params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
    f.add_double("mirror-tolerance", &params.mirror_tolerance_deg,
                 "pairs vote only if their edge orientations mirror about the axis within DEG (0: off)");
    f.add_bool("mirror-polarity", &params.mirror_polarity,
               "with --mirror-tolerance: the gradients' polarity must mirror too (same contrast on both sides)");
    f.add_int("threads", &params.threads, "threads across angles");
    f.add_int("suppress-r", &params.suppress_r, "non-maximum suppression half-size in R, px");
    f.add_int("suppress-theta", &params.suppress_theta, "non-maximum suppression half-size in theta, degrees");
    int verify = 0;
    f.add_int("verify", &verify, "busy tables: verify the --lines peaks (local support, mirrored colour) and publish the best N; 0: off");
    f.add_double("appearance-tolerance", &options.verify_params.colour_tolerance,
                 "with --verify: L1 BGR difference under which mirrored colour samples agree");
    f.add_double("support-gap", &options.verify_params.support_gap_px,
                 "with --verify: gaps up to this many px join bands into a line's support segment (0: the largest band alone)");
    std::string upright_calibration;
    std::vector<double> upright_table;
    double upright_tilt = 2;
    std::string column_calibration;
    geometry::Column column;
    column.radius = robot::SafetyConfig{}.pedestal_radius;  // the PUMA 260's pedestal, as the world models it
    column.height = 0.40;   // the shoulder (0.33 m) and the ball on it
    f.add_string("upright-calibration", &upright_calibration,
                 "with --verify: verify only peaks that can be upright axes on the table of this rig file (its table_plane "
                 "unless --upright-table); input channels must end in LEFT / RIGHT");
    f.add_string("column-calibration", &column_calibration,
                 "leave the arm's base column out of the edges: its place from this rig file's arm_base and table_plane "
                 "(input channels must end in LEFT / RIGHT)");
    f.add_double("column-radius", &column.radius, "with --column-calibration: the column's radius, m");
    f.add_double("column-height", &column.height, "with --column-calibration: its height above the table, m");
    int column_band = 4;
    f.add_int("column-band", &column_band, "with --column-calibration: leave out only a band this many px either side of the "
                                           "column's outline (its silhouette edges; an object in front of it keeps its own); "
                                           "0: the whole column");
    f.add_doubles("upright-table", &upright_table, 4, "with --upright-calibration: table plane NX NY NZ D (right camera frame, m)");
    f.add_double("upright-max-tilt", &upright_tilt, "with --upright-calibration: largest angle (deg) between the table normal "
                 "and the plane through the camera and a line");
    std::string table_texture_calibration;
    geometry::TableTextureParams table_texture;
    double table_texture_skew_ms = 20;
    f.add_string("table-texture-calibration", &table_texture_calibration,
                 "leave the table's own texture out of the edges: where the two cameras' images agree through this rig "
                 "file's table_plane (needs one ..._LEFT and one ..._RIGHT input)");
    f.add_double("table-texture-difference", &table_texture.max_difference,
                 "with --table-texture-calibration: largest mean grey difference of the two views for the table's pixels");
    f.add_int("table-texture-window", &table_texture.window_radius,
              "with --table-texture-calibration: half-size of the window the views are compared over, px");
    f.add_double("table-texture-skew-ms", &table_texture_skew_ms,
                 "with --table-texture-calibration: the two cameras' images of one moment differ in time by at most this");
    std::string reach_calibration;
    symmetry_service::Options::Reach reach;
    f.add_string("reach-calibration", &reach_calibration,
                 "only lines standing within reach: whose support segment's foot is on this rig file's table_plane "
                 "within --reach-radius of its arm_base (input channels must end in LEFT / RIGHT)");
    f.add_double("reach-radius", &reach.radius, "with --reach-calibration: the radius, m (the workspace ring's outer "
                                                "edge and a margin: an object's lowest edges stand a little above the table)");
    f.add_double("reach-inner-radius", &reach.inner_radius,
                 "with --reach-calibration: drop lines whose foot is nearer the arm_base than this, m (its base "
                 "column's lines; 0: keep them)");
    f.add_int("reach-keep", &reach.keep, "with --reach-calibration: publish at most this many of the lines standing within reach (0: all)");
    f.add_double("reach-column-px", &reach.column_px,
                 "with --reach-keep: a line within this many pixels of the image of the arm's base column (the "
                 "upright axis at arm_base) is published without counting among the kept (0: it counts)");
    f.add_double("reach-max-tilt", &reach.max_tilt_deg,
                 "with --reach-calibration: drop lines whose plane leans more than this many degrees from the table's "
                 "normal (none can be an upright object's axis) before --reach-keep; 0: keep them");
    f.add_double("reach-one-per-place", &reach.one_per_place_px,
                 "with --reach-calibration: before --reach-keep, offer each place in the image once before any twice: a "
                 "line within this many pixels of a stronger one (where their supports overlap) waits behind the rest; 0: off");
    std::string explored_calibration;
    symmetry_service::Options::Explored explored;
    f.add_string("explored-calibration", &explored_calibration,
                 "leave the objects a survey has explored out of the edges: each CANDIDATES_REQUEST's explored places, "
                 "on this rig file's table_plane, its arm_base the table frame's origin (input channels must end in LEFT / RIGHT)");
    f.add_double("explored-radius", &explored.radius, "with --explored-calibration: each explored object's radius, m "
                                                      "(the largest expected and the place's error)");
    f.add_double("explored-height", &explored.height, "with --explored-calibration: its height above the table, m");
    f.add_int("explored-band", &explored.band_px, "with --explored-calibration: leave out only a band this many px either "
                                                  "side of each explored object's outline; 0: its whole image region");
    f.add_bool("colour-edges", &edge.colour, "Canny on the colour image (the channel that changes most)");
    f.add_int("contours", &options.contours, "also segment the contours of the top N lines (CONTOURS_*); 0: off");
    if (!service.parse(argc, argv)) return 0;
    if (verify < 0) throw FlagError("--verify must be >= 0");
    options.verify = verify > 0;
    options.verify_params.keep = verify;
    edge.canny_low = canny[0];
    edge.canny_high = canny[1];
    try {
      symmetry::validate(params);
      symmetry::validate(edge);
      symmetry::validate(options.verify_params);
    } catch (const std::invalid_argument& e) {
      throw FlagError(e.what());
    }
    if (options.contours < 0) throw FlagError("--contours must be >= 0");
    options.inputs = split_list(inputs);
    if (!upright_calibration.empty()) {
      if (!options.verify) throw FlagError("--upright-calibration needs --verify N");
      if (!(upright_tilt >= 0 && upright_tilt <= 90)) throw FlagError("--upright-max-tilt must be in [0, 90]");
      symmetry_service::Options::Upright upright;
      try {
        upright.rig = geometry::load_rig(upright_calibration);
        if (!upright_table.empty()) {
          upright.table = geometry::plane_from_coefficients(
              Eigen::Vector4d(upright_table[0], upright_table[1], upright_table[2], upright_table[3]));
        } else {
          const std::optional<geometry::Plane> table = geometry::load_workspace(upright_calibration).table;
          if (!table) throw std::invalid_argument(upright_calibration + " has no table_plane; give --upright-table");
          upright.table = *table;
        }
        for (const auto& channel : options.inputs) symmetry_service::side_of_channel(channel);
      } catch (const std::exception& e) {
        throw FlagError(std::string("--upright-calibration: ") + e.what());
      }
      upright.max_tilt_deg = upright_tilt;
      options.upright = upright;
    }
    if (!column_calibration.empty()) {
      try {
        if (column_band < 0) throw std::invalid_argument("--column-band must be >= 0");
        const RigOnTable on_table = rig_on_table(column_calibration, options.inputs);
        column.foot = on_table.arm_base;
        for (const geometry::Side side : {geometry::Side::Left, geometry::Side::Right})
          (side == geometry::Side::Left ? options.column_mask_left : options.column_mask_right) =
              geometry::columns_mask(on_table.rig, side, on_table.table, {column}, 4, column_band);
      } catch (const std::exception& e) {
        throw FlagError(std::string("--column-calibration: ") + e.what());
      }
    }
    if (!table_texture_calibration.empty()) {
      try {
        geometry::validate(table_texture);
        if (!(table_texture_skew_ms >= 0)) throw std::invalid_argument("--table-texture-skew-ms must be >= 0");
        const geometry::StereoRig rig = geometry::load_rig(table_texture_calibration);
        const geometry::Workspace scene = geometry::load_workspace(table_texture_calibration);
        if (!scene.table) throw std::invalid_argument(table_texture_calibration + " has no table_plane");
        int left = 0, right = 0;
        for (const auto& channel : options.inputs)
          (symmetry_service::side_of_channel(channel) == geometry::Side::Left ? left : right) += 1;
        if (left != 1 || right != 1)
          throw std::invalid_argument("needs exactly one ..._LEFT and one ..._RIGHT input channel");
        options.table_texture = symmetry_service::Options::TableTexture{
            geometry::plane_warp(rig, geometry::Side::Left, *scene.table),
            geometry::plane_warp(rig, geometry::Side::Right, *scene.table), table_texture,
            static_cast<int64_t>(table_texture_skew_ms * 1000)};
      } catch (const std::exception& e) {
        throw FlagError(std::string("--table-texture-calibration: ") + e.what());
      }
    }
    if (!explored_calibration.empty()) {
      try {
        if (!(explored.radius > 0) || !(explored.height > 0))
          throw std::invalid_argument("--explored-radius and --explored-height must be > 0");
        if (explored.band_px < 0) throw std::invalid_argument("--explored-band must be >= 0");
        const RigOnTable on_table = rig_on_table(explored_calibration, options.inputs);
        explored.rig = on_table.rig;
        explored.table = on_table.table;
        explored.arm_base = on_table.arm_base;
        options.explored = explored;
      } catch (const std::exception& e) {
        throw FlagError(std::string("--explored-calibration: ") + e.what());
      }
    }
    if (!reach_calibration.empty()) {
      try {
        if (!(reach.radius > 0)) throw std::invalid_argument("--reach-radius must be > 0");
        if (!(reach.inner_radius >= 0 && reach.inner_radius < reach.radius))
          throw std::invalid_argument("--reach-inner-radius must be >= 0 and below --reach-radius");
        if (reach.keep < 0) throw std::invalid_argument("--reach-keep must be >= 0");
        if (!(reach.column_px >= 0)) throw std::invalid_argument("--reach-column-px must be >= 0");
        if (!(reach.max_tilt_deg >= 0 && reach.max_tilt_deg <= 90))
          throw std::invalid_argument("--reach-max-tilt must be in [0, 90]");
        if (!(reach.one_per_place_px >= 0 && std::isfinite(reach.one_per_place_px)))
          throw std::invalid_argument("--reach-one-per-place must be >= 0 (pixels)");
        const RigOnTable on_table = rig_on_table(reach_calibration, options.inputs);
        reach.rig = on_table.rig;
        reach.table = on_table.table;
        reach.centre = on_table.arm_base;
        options.reach = reach;
      } catch (const std::exception& e) {
        throw FlagError(std::string("--reach-calibration: ") + e.what());
      }
    }
    service.start();
    service.watch_heartbeats({"camera"});  // its input: say so when the camera goes quiet
    service.watch_streams(options.inputs);  // and when its frames stop while it lives (a stall, a file's end)
    const symmetry_service::Handlers handlers(service, options);
    return service.run();
  });
}

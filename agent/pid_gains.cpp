#include "agent/pid_gains.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/config/table.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {
namespace {

/// A gain, limit or radius: a magnitude, >= 0.
template <class Member>
void gain(config::Table<PidGains>& t, const std::string& key, Member member,
          const std::string& unit, const std::string& doc) {
  t.field(key, member, unit, doc).range(0.0);
}

/// Surge, sway and heave: outer position loops, their speed limits and the inner velocity loop.
void add_translation_fields(config::Table<PidGains>& t) {
  using G = PidGains;
  gain(t, "surge_position_gain_per_s", &G::surge_position_gain_per_s, "1/s",
       "u_ref = gain * goal error along body x");
  gain(t, "surge_speed_max_mps", &G::surge_speed_max_mps, "m/s", "surge speed reference limit");
  gain(t, "sway_position_gain_per_s", &G::sway_position_gain_per_s, "1/s",
       "v_ref = gain * lateral error (vehicles with sway authority)");
  gain(t, "sway_speed_max_mps", &G::sway_speed_max_mps, "m/s", "sway speed reference limit");
  gain(t, "heave_position_gain_per_s", &G::heave_position_gain_per_s, "1/s",
       "w_ref = gain * goal error along body z");
  gain(t, "heave_speed_max_mps", &G::heave_speed_max_mps, "m/s", "heave speed reference limit");
  gain(t, "velocity_gain_per_s", &G::velocity_gain_per_s, "1/s",
       "inner loops: F = m_eff * gain * (v_ref - v) + drag feed-forward");
  gain(t, "position_integral_gain_per_s2", &G::position_integral_gain_per_s2, "1/s^2",
       "F_i = m_eff * gain * integral of the position error");
  gain(t, "integral_radius_m", &G::integral_radius_m, "m",
       "the position integral runs only this near the goal");
  gain(t, "integral_force_max_n", &G::integral_force_max_n, "N",
       "anti-windup clamp of the integral force, per axis");
}

/// Heading, the reverse radius, pitch and roll.
void add_attitude_fields(config::Table<PidGains>& t) {
  using G = PidGains;
  gain(t, "yaw_gain_per_s", &G::yaw_gain_per_s, "1/s", "r_ref = gain * heading error");
  gain(t, "yaw_rate_max_rad_s", &G::yaw_rate_max_rad_s, "rad/s", "yaw-rate reference limit");
  gain(t, "yaw_rate_gain_per_s", &G::yaw_rate_gain_per_s, "1/s", "inner yaw-rate loop");
  gain(t, "yaw_integral_gain_per_s2", &G::yaw_integral_gain_per_s2, "1/s^2",
       "integral of the heading error (a steady yaw moment)");
  gain(t, "yaw_integral_moment_max_nm", &G::yaw_integral_moment_max_nm, "N m",
       "anti-windup clamp of the yaw integral");
  gain(t, "yaw_integral_window_rad", &G::yaw_integral_window_rad, "rad",
       "the yaw integral runs only within this heading error");
  gain(t, "heading_hold_radius_m", &G::heading_hold_radius_m, "m",
       "nearer (horizontally) than this the heading reference is frozen");
  gain(t, "reverse_radius_m", &G::reverse_radius_m, "m",
       "nearer than this surge may back up (station keeping)");
  gain(t, "pitch_max_rad", &G::pitch_max_rad, "rad",
       "nose toward the goal by at most this (vehicles with pitch authority)");
  gain(t, "pitch_gain_per_s", &G::pitch_gain_per_s, "1/s", "q_ref = gain * (theta_ref - theta)");
  gain(t, "pitch_rate_gain_per_s", &G::pitch_rate_gain_per_s, "1/s", "inner pitch-rate loop");
  gain(t, "roll_gain_per_s", &G::roll_gain_per_s, "1/s",
       "p_ref = gain * (0 - phi) (vehicles with roll authority; 0: off)");
  gain(t, "roll_rate_gain_per_s", &G::roll_rate_gain_per_s, "1/s",
       "inner roll-rate loop (0: no roll loop)");
}

config::Table<PidGains> make_pid_gains_table() {
  config::Table<PidGains> t("pid gains",
                            "gains of the PID way-point controller (config/vehicles/X.pid.yaml)");
  add_translation_fields(t);
  add_attitude_fields(t);
  // The range check lets infinity through: a gain must also be finite.
  t.validate([fields = t.fields()](const config::Section& section, PidGains& gains) {
    for (const config::Field<PidGains>& f : fields) {
      if (!std::isfinite(config::shown_number(f.show(gains)))) {
        section.fail(f.key, "expected a finite number, got " + f.show(gains));
      }
    }
  });
  return t;
}

}  // namespace

const config::Table<PidGains>& pid_gains_table() {
  static const config::Table<PidGains> table = make_pid_gains_table();
  return table;
}

void check_pid_gains(const PidGains& gains) {
  PidGains copy = gains;  // Field::show takes a mutable reference
  for (const config::Field<PidGains>& f : pid_gains_table().fields()) {
    const double value = config::shown_number(f.show(copy));
    if (!std::isfinite(value) || value < 0) {
      throw std::invalid_argument("PID gain " + f.key + " must be finite and >= 0, got " +
                                  f.show(copy));
    }
  }
}

std::string pid_gains_path(const std::string& vehicle_file) {
  for (const char* extension : {".yaml", ".yml"}) {
    const std::string ext(extension);
    if (vehicle_file.size() > ext.size() &&
        vehicle_file.compare(vehicle_file.size() - ext.size(), ext.size(), ext) == 0) {
      return vehicle_file.substr(0, vehicle_file.size() - ext.size()) + ".pid.yaml";
    }
  }
  return vehicle_file + ".pid.yaml";
}

PidGains read_pid_gains_file(const std::string& path) {
  PidGains gains;
  pid_gains_table().read(config::load_file(path), gains);
  return gains;
}

std::string pid_gains_text(const PidGains& gains, const std::string& header) {
  std::string text;
  std::size_t begin = 0;
  while (begin < header.size()) {
    std::size_t end = header.find('\n', begin);
    if (end == std::string::npos) end = header.size();
    const std::string line = header.substr(begin, end - begin);
    text += line.empty() ? "#\n" : "# " + line + "\n";
    begin = end + 1;
  }
  PidGains copy = gains;
  for (const config::Field<PidGains>& f : pid_gains_table().fields()) {
    text += f.key + ": " + f.show(copy) + "  # " + f.unit + ": " + f.doc + "\n";
  }
  return text;
}

void write_pid_gains_file(const std::string& path, const PidGains& gains,
                          const std::string& header) {
  std::ofstream out(path, std::ios::trunc);
  out << pid_gains_text(gains, header);
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write the PID gains file");
}

VehiclePidGains pid_gains_for(const sim::VehicleModel& model) {
  VehiclePidGains result;
  if (model.source_file.empty()) return result;  // built in code: no file beside it
  result.file = pid_gains_path(model.source_file);
  std::error_code ec;
  if (!std::filesystem::exists(result.file, ec)) return result;
  result.gains = read_pid_gains_file(result.file);
  result.from_file = true;
  return result;
}

}  // namespace auvrl::agent

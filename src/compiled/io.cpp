/// \file src/compiled/io.cpp
/// nhdyn::compiled (include/nhdyn/config.hpp): the file loaders' definitions, compiled once.
/// The headers define them here (NHDYN_COMPILED_SOURCE); a program that links
/// nhdyn::compiled sees their declarations only (NHDYN_COMPILED).
#define NHDYN_COMPILED_SOURCE 1  // NHDYN_PART_IO (include/nhdyn/config.hpp)
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>

// The loaders are function templates with one unused parameter (config.hpp): instantiated here.
namespace nhdyn::io {
template tree<double> parse_urdf<>(const std::string&, const std::string&, urdf_options);
template tree<double> load_urdf<>(const std::string&, urdf_options);
template robot_model lock_robot<>(robot_model, const std::vector<std::pair<std::string, double>>&, const std::string&);
template robot_model as_robot<>(const model<double>&, const std::string&);
template robot_model parse_robot_file<>(const std::string&, const std::string&, urdf_options);
template std::optional<robot_constraint> constraint_on<>(const robot_model&, const tree<double>&);
template robot_model load_robot_file<>(const std::string&, urdf_options);
template robot_model load_robot<>(const std::string&);
}  // namespace nhdyn::io

/// The alignment check of detail/compiled_abi.hpp: programs built with other flags do not link.
extern "C" const int NHDYN_COMPILED_ABI_SYMBOL = EIGEN_MAX_STATIC_ALIGN_BYTES;

// TetGen run as a separate program (tetgen_process.h): the complex written as a .smesh file into a
// private temporary directory, `tetgen` started there with posix_spawnp (an argument vector, no shell),
// and its .node / .ele / .face files read back.
#include "core/meshing/tetgen_process.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace soft_body_sim
{
namespace
{
namespace fs = std::filesystem;

/// A directory of its own under the system's temporary directory (mkdtemp: mode 0700, a fresh name),
/// removed with everything in it when it goes out of scope.
class TemporaryDirectory
{
public:
  TemporaryDirectory()
  {
    std::string pattern = (fs::temp_directory_path() / "soft_body_sim_tetgen_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("cannot make a temporary directory " + pattern + ": " + std::strerror(errno));
    path_ = pattern;
  }
  ~TemporaryDirectory()
  {
    std::error_code ignored;  // a destructor cannot throw; a leftover directory is harmless
    fs::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  const fs::path& path() const { return path_; }

private:
  fs::path path_;
};

/// TetGen's .smesh format: the vertices numbered from 0, then the facets, each with the boundary
/// marker (its index + 1) that `tetgen -d` reports intersecting faces by; no holes, no regions.
void writeSmesh(const Plc& plc, const fs::path& path)
{
  std::ofstream out(path);
  out << std::setprecision(17);  // round-trips every double
  out << plc.vertices.size() << " 3 0 0\n";
  for (std::size_t v = 0; v < plc.vertices.size(); ++v)
    out << v << ' ' << plc.vertices[v].x() << ' ' << plc.vertices[v].y() << ' ' << plc.vertices[v].z() << '\n';
  out << plc.facets.size() << " 1\n";
  for (std::size_t f = 0; f < plc.facets.size(); ++f)
  {
    out << plc.facets[f].size();
    for (int v : plc.facets[f])
      out << ' ' << v;
    out << ' ' << f + 1 << '\n';
  }
  out << "0\n0\n";
  if (!out)
    throw std::runtime_error("cannot write tetgen's input " + path.string());
}

/// The last line tetgen printed into `log`, for an error message.
std::string lastLine(const fs::path& log)
{
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty())
      last = line;
  return last.empty() ? "it printed nothing" : "it printed '" + last + "'";
}

/// Runs `tetgen <switches> <input>` in input's directory, its output into tetgen.log there; throws
/// unless it exits with status 0.
void runTetgen(const std::string& switches, const fs::path& input)
{
  const fs::path log = input.parent_path() / "tetgen.log";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::string program = "tetgen", options = switches, file = input.string();
  char* argv[] = { program.data(), options.data(), file.data(), nullptr };
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error == ENOENT)
    throw std::runtime_error("the tetgen program is not on PATH: install the Debian package tetgen");
  if (spawn_error != 0)
    throw std::runtime_error(std::string("cannot start tetgen: ") + std::strerror(spawn_error));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      throw std::runtime_error(std::string("cannot wait for tetgen: ") + std::strerror(errno));
  const std::string command = "tetgen " + switches;
  // TetGen 1.5 stops on an error by throwing an int that nothing catches: it aborts (SIGABRT).
  if (WIFSIGNALED(status))
    throw std::runtime_error(command + " stopped by signal " + std::to_string(WTERMSIG(status)) +
                             " (the surface has facets too close or crossing for it to mesh); " + lastLine(log));
  if (WEXITSTATUS(status) != 0)
    throw std::runtime_error(command + " exited with status " + std::to_string(WEXITSTATUS(status)) + "; " +
                             lastLine(log));
}

/// Opens one of tetgen's output files and reads its header of `fields` counts.
std::ifstream openOutput(const fs::path& path, std::vector<long>& header, std::size_t fields)
{
  std::ifstream in(path);
  header.assign(fields, 0);
  for (long& field : header)
    in >> field;
  if (!in)
    throw std::runtime_error("cannot read tetgen's output " + path.string());
  return in;
}

/// A .node file: "count 3 attributes markers", then "index x y z [attributes] [marker]" per node.
std::vector<Eigen::Vector3d> readNodes(const fs::path& path)
{
  std::vector<long> header;
  std::ifstream in = openOutput(path, header, 4);
  std::vector<Eigen::Vector3d> nodes(static_cast<std::size_t>(header[0]));
  double ignored = 0.0;
  for (Eigen::Vector3d& node : nodes)
  {
    long index = 0;
    in >> index >> node.x() >> node.y() >> node.z();
    for (long k = 0; k < header[2] + header[3]; ++k)
      in >> ignored;
  }
  if (!in)
    throw std::runtime_error("cannot read tetgen's output " + path.string());
  return nodes;
}

/// An .ele file: "count 4 attributes", then "index a b c d [attributes]" per tetrahedron.
std::vector<std::array<int, 4>> readTets(const fs::path& path, std::size_t nodes)
{
  std::vector<long> header;
  std::ifstream in = openOutput(path, header, 3);
  if (header[1] != 4)
    throw std::runtime_error("tetgen's output " + path.string() + " holds elements of " +
                             std::to_string(header[1]) + " nodes, not tetrahedra of 4");
  std::vector<std::array<int, 4>> tets(static_cast<std::size_t>(header[0]));
  double ignored = 0.0;
  for (std::array<int, 4>& tet : tets)
  {
    long index = 0;
    in >> index >> tet[0] >> tet[1] >> tet[2] >> tet[3];
    for (long k = 0; k < header[2]; ++k)
      in >> ignored;
    for (int node : tet)
      if (node < 0 || static_cast<std::size_t>(node) >= nodes)
        in.setstate(std::ios::failbit);
  }
  if (!in)
    throw std::runtime_error("cannot read tetgen's output " + path.string());
  return tets;
}

/// A .face file's boundary markers: "count markers", then "index a b c marker" per face.
std::set<int> readFaceMarkers(const fs::path& path)
{
  std::vector<long> header;
  std::ifstream in = openOutput(path, header, 2);
  std::set<int> markers;
  for (long k = 0; k < header[0]; ++k)
  {
    long index = 0, a = 0, b = 0, c = 0;
    int marker = 0;
    in >> index >> a >> b >> c >> marker;
    markers.insert(marker);
  }
  if (!in)
    throw std::runtime_error("cannot read tetgen's output " + path.string());
  return markers;
}

}  // namespace

std::vector<int> intersectingFacets(const Plc& plc)
{
  const TemporaryDirectory directory;
  const fs::path input = directory.path() / "surface.smesh";
  writeSmesh(plc, input);
  // -d: detect intersecting facets and only that; -z: number from 0; -Q: quiet. It writes a .face file
  // of the crossing faces (with their facets' markers) only when it finds some.
  runTetgen("-pdzQ", input);
  const fs::path faces = directory.path() / "surface.1.face";
  std::vector<int> facets;
  if (fs::exists(faces))
    for (int marker : readFaceMarkers(faces))
      facets.push_back(marker - 1);
  return facets;
}

TetMesh tetrahedralise(const Plc& plc, double max_volume)
{
  const TemporaryDirectory directory;
  const fs::path input = directory.path() / "solid.smesh";
  writeSmesh(plc, input);
  // -p: mesh the complex; -z: number from 0; -F: no .face file (the surface is found from the tets);
  // -Q: quiet; -q1.414: radius-edge ratio <= sqrt 2; -a: the volume bound, last so that its number ends
  // the switches.
  std::ostringstream switches;
  switches << std::setprecision(17) << "-pzFQq1.414a" << max_volume;
  runTetgen(switches.str(), input);
  TetMesh mesh;
  mesh.nodes = readNodes(directory.path() / "solid.1.node");
  mesh.tets = readTets(directory.path() / "solid.1.ele", mesh.nodes.size());
  return mesh;
}

}  // namespace soft_body_sim

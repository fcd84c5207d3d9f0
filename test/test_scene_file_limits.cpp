// The files a scene names are checked before they are read: a scene file or a mesh larger than its kind
// may be is refused by its size, unread; a FIFO or a directory is refused by its type, unopened; and a
// scene file under the size limit that lists more nodes than a scene may have is refused before yaml-cpp
// builds its tree. Each load runs in a forked child, so that its peak memory is its own (getrusage in the
// child, before and after) and a load that blocks (a FIFO) is ended by alarm() and fails the test instead
// of hanging the suite.
#include "soft_body_sim/scene/scene_loader.h"
#include "soft_body_sim/core/contact/mesh_field.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace soft_body_sim
{
namespace
{
namespace fs = std::filesystem;

/// A load that did not finish within this many seconds is taken to block. Every refusal here takes
/// seconds at most (the slowest, the scan of a million nodes, ~2 s); a FIFO blocks an open forever.
constexpr unsigned kTimeout = 60;

/// A folder of its own under the system's temporary one, removed with everything in it.
class TempFolder
{
public:
  TempFolder()
  {
    std::string pattern = (fs::temp_directory_path() / "scene_file_limits_XXXXXX").string();
    if (!mkdtemp(pattern.data()))
      throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempFolder() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

private:
  fs::path path_;
};

/// A sparse file of `bytes` bytes of zeros: it takes no disk, but reads as that many bytes.
void makeSparseFile(const std::string& path, std::uintmax_t bytes)
{
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  ASSERT_GE(fd, 0) << path;
  ASSERT_EQ(ftruncate(fd, static_cast<off_t>(bytes)), 0) << path;
  close(fd);
}

void writeFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// A scene of one collider `shape: mesh` reading `mesh` (at line 3) and one custom body.
std::string meshColliderScene(const std::string& mesh)
{
  return "colliders:\n  - {name: part, shape: mesh,\n     mesh: " + mesh +
         "}\nbodies:\n  - {name: dot, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}\n";
}

/// What loadSceneFile did in a child process.
struct ChildLoad
{
  bool finished = false;  ///< false: it was still loading after kTimeout seconds
  std::string error;      ///< the SceneError's message; empty if it loaded
  long added_bytes = 0;   ///< how far its peak resident memory rose above where it stood before the load
};

ChildLoad loadInChild(const std::string& path)
{
  int channel[2];
  if (pipe(channel) != 0)
    throw std::runtime_error("pipe failed");
  const pid_t child = fork();
  if (child < 0)
    throw std::runtime_error("fork failed");
  if (child == 0)
  {
    close(channel[0]);
    alarm(kTimeout);  // SIGALRM ends the child
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const long before = usage.ru_maxrss;  // [KiB] on Linux
    std::string error;
    try
    {
      loadSceneFile(path);
    }
    catch (const SceneError& e)
    {
      error = e.what();
    }
    catch (const std::exception& e)
    {
      error = std::string("not a SceneError: ") + e.what();
    }
    getrusage(RUSAGE_SELF, &usage);
    const std::string report = std::to_string((usage.ru_maxrss - before) * 1024) + "\n" + error;
    ssize_t written = 0;
    while (written < static_cast<ssize_t>(report.size()))
    {
      const ssize_t n = write(channel[1], report.data() + written, report.size() - written);
      if (n <= 0)
        break;
      written += n;
    }
    _exit(0);  // not exit(): the child must not run the test binary's exit handlers
  }
  close(channel[1]);
  std::string report;
  char buffer[4096];
  for (ssize_t n; (n = read(channel[0], buffer, sizeof buffer)) > 0;)
    report.append(buffer, static_cast<std::size_t>(n));
  close(channel[0]);
  int status = 0;
  waitpid(child, &status, 0);
  ChildLoad load;
  load.finished = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  const std::size_t newline = report.find('\n');
  if (load.finished && newline != std::string::npos)
  {
    load.added_bytes = std::stol(report.substr(0, newline));
    load.error = report.substr(newline + 1);
  }
  // In the XML report (--gtest_output=xml), to see how far each load stayed under its bound.
  testing::Test::RecordProperty(fs::path(path).filename().string() + "_peak_rss_added_bytes",
                                std::to_string(load.added_bytes));
  return load;
}

bool startsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }
bool contains(const std::string& text, const std::string& word) { return text.find(word) != std::string::npos; }

TEST(SceneFileLimits, ASceneFileOverTheSizeLimitIsRefusedUnread)
{
  const TempFolder folder;
  const std::string path = folder / "huge.yaml";
  const std::uintmax_t bytes = kMaxSceneFileBytes + 1;
  makeSparseFile(path, bytes);
  const ChildLoad load = loadInChild(path);
  ASSERT_TRUE(load.finished) << "the load did not finish in " << kTimeout << " s";
  EXPECT_TRUE(startsWith(load.error, path + ": cannot open scene file: ")) << load.error;
  EXPECT_TRUE(contains(load.error, "kMaxSceneFileBytes")) << load.error;
  // Refused by its size before it is read, so not even one copy of it is in memory (reading it would
  // take its size at least).
  EXPECT_LT(load.added_bytes, static_cast<long>(bytes / 4)) << load.error;
}

TEST(SceneFileLimits, AMeshFileOverTheSizeLimitIsRefusedUnread)
{
  const TempFolder folder;
  const std::uintmax_t bytes = std::uintmax_t{ 3 } << 30;  // 3 GiB
  ASSERT_GT(bytes, kMaxMeshFileBytes);
  makeSparseFile(folder / "huge.stl", bytes);
  // The same reader takes a mesh collider's file and a solid's surface.
  const std::string collider = folder / "collider.yaml", solid = folder / "solid.yaml";
  writeFile(collider, meshColliderScene("huge.stl"));
  writeFile(solid, "bodies:\n  - name: part\n    type: volume\n    shape: mesh\n    mesh: huge.stl\n"
                   "    resolution: 0.1\n    position: [0, 0, 0]\n    youngs_modulus: 1.0e5\n    density: 1000\n");
  for (const auto& [scene, location] : { std::make_pair(collider, collider + ":3: colliders[0].mesh: "),
                                         std::make_pair(solid, solid + ":5: bodies[0].mesh: ") })
  {
    const ChildLoad load = loadInChild(scene);
    ASSERT_TRUE(load.finished) << scene << ": the load did not finish in " << kTimeout << " s";
    EXPECT_TRUE(startsWith(load.error, location)) << load.error;
    EXPECT_TRUE(contains(load.error, "huge.stl")) << load.error;
    EXPECT_TRUE(contains(load.error, "kMaxMeshFileBytes")) << load.error;
    EXPECT_LT(load.added_bytes, static_cast<long>(bytes / 4)) << load.error;
  }
}

TEST(SceneFileLimits, AFifoIsRefusedWithoutBlocking)
{
  const TempFolder folder;
  ASSERT_EQ(mkfifo((folder / "pipe.stl").c_str(), 0600), 0);
  const std::string scene = folder / "scene.yaml";
  writeFile(scene, meshColliderScene("pipe.stl"));
  const ChildLoad mesh = loadInChild(scene);
  ASSERT_TRUE(mesh.finished) << "blocked on a FIFO as a mesh for " << kTimeout << " s";
  EXPECT_TRUE(startsWith(mesh.error, scene + ":3: colliders[0].mesh: ")) << mesh.error;
  EXPECT_TRUE(contains(mesh.error, "pipe.stl")) << mesh.error;
  EXPECT_TRUE(contains(mesh.error, "FIFO")) << mesh.error;

  // The scene file itself.
  const ChildLoad self = loadInChild(folder / "pipe.stl");
  ASSERT_TRUE(self.finished) << "blocked on a FIFO as the scene file for " << kTimeout << " s";
  EXPECT_EQ(self.error, folder / "pipe.stl" + ": cannot open scene file: it is a FIFO (named pipe), not a regular file");
}

TEST(SceneFileLimits, ADirectoryAsAMeshIsRefused)
{
  const TempFolder folder;
  fs::create_directory(folder / "part.stl");
  const std::string scene = folder / "scene.yaml";
  writeFile(scene, meshColliderScene("part.stl"));
  const ChildLoad load = loadInChild(scene);
  ASSERT_TRUE(load.finished);
  EXPECT_TRUE(startsWith(load.error, scene + ":3: colliders[0].mesh: ")) << load.error;
  EXPECT_TRUE(contains(load.error, "part.stl")) << load.error;
  EXPECT_TRUE(contains(load.error, "directory")) << load.error;
}

/// `nodes` items "*n" (an alias of one node, 4 bytes each), `count` of them after the anchor `&n`.
std::string aliasedNodes(long long count)
{
  std::string text = "[&n {position: [0, 0, 0], mass: 1}";
  for (long long node = 1; node < count; ++node)
    text += node % 16 == 0 ? ",\n      *n" : ", *n";
  return text + "]";
}

TEST(SceneFileLimits, ListedNodesOverTheNodeLimitAreRefusedBeforeTheTreeIsBuilt)
{
  // One more node than a scene may have, listed in one body, or in a list that a second body names by
  // its anchor; then a comment up to the size limit, so that the file is as large as a scene file may be.
  const long long half = kMaxSceneNodes / 2 + 1;
  const std::string one_list = "bodies:\n  - name: blob\n    type: custom\n    nodes: " +
                               aliasedNodes(kMaxSceneNodes + 1) + "\n";
  const std::string shared_list = "bodies:\n  - name: blob\n    type: custom\n    nodes: &half " +
                                  aliasedNodes(half) + "\n  - name: twin\n    type: custom\n    nodes: *half\n";
  const std::size_t twin_nodes = shared_list.find("nodes: *half");
  const std::string twin_line = std::to_string(1 + std::count(shared_list.begin(), shared_list.begin() + twin_nodes, '\n'));
  const TempFolder folder;
  for (const auto& [text, location] : { std::make_pair(one_list, std::string(":4: bodies[0].nodes: ")),
                                        std::make_pair(shared_list, ":" + twin_line + ": bodies[1].nodes: ") })
  {
    const std::string path = folder / "many_nodes.yaml";
    {
      std::string padded = text + "#";
      padded.resize(static_cast<std::size_t>(kMaxSceneFileBytes) - 1, 'x');
      writeFile(path, padded + "\n");
    }
    const long bytes = static_cast<long>(fs::file_size(path));
    const ChildLoad load = loadInChild(path);
    ASSERT_TRUE(load.finished) << "the load did not finish in " << kTimeout << " s";
    EXPECT_TRUE(startsWith(load.error, path + location)) << load.error;
    EXPECT_TRUE(contains(load.error, "nodes")) << load.error;
    EXPECT_TRUE(contains(load.error, "more than " + std::to_string(kMaxSceneNodes))) << load.error;
    // The scan's words: refused from the parser's events, not by the body reader after the tree is built.
    EXPECT_TRUE(contains(load.error, "listed in its custom bodies")) << load.error;
    EXPECT_LT(load.added_bytes, 2 * bytes) << load.error;
  }
}

}  // namespace
}  // namespace soft_body_sim

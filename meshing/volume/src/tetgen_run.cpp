// TetGen in a forked child (see tetgen_run.hpp for why).
#include "tetgen_run.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <csignal>
#include <cstring>
#include <new>

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#define TETLIBRARY  // the library's interface: errors thrown, not exit()
#include <tetgen.h>

namespace skinmesh::detail {
namespace {

// The complex in TetGen's input structure (zero-based; tetgenio frees
// what is allocated here with delete[]).
void fill_tetgenio(const Plc& plc, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(plc.points.size());
  in.pointlist = new REAL[3 * plc.points.size()];
  for (size_t i = 0; i < plc.points.size(); ++i)
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + static_cast<size_t>(k)] = plc.points[i][k];
  in.numberoffacets = static_cast<int>(plc.facets.size());
  in.facetlist = new tetgenio::facet[plc.facets.size()];
  in.facetmarkerlist = new int[plc.facets.size()];
  for (size_t f = 0; f < plc.facets.size(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = plc.facets[f][static_cast<size_t>(k)];
    in.facetmarkerlist[f] = plc.markers[f];
  }
  in.numberofholes = static_cast<int>(plc.holes.size());
  in.holelist = plc.holes.empty() ? nullptr : new REAL[3 * plc.holes.size()];
  for (size_t h = 0; h < plc.holes.size(); ++h)
    for (int k = 0; k < 3; ++k) in.holelist[3 * h + static_cast<size_t>(k)] = plc.holes[h][k];
  in.numberofregions = static_cast<int>(plc.regions.size());
  in.regionlist = plc.regions.empty() ? nullptr : new REAL[5 * plc.regions.size()];
  for (size_t r = 0; r < plc.regions.size(); ++r) {
    for (int k = 0; k < 3; ++k) in.regionlist[5 * r + static_cast<size_t>(k)] = plc.regions[r].point[k];
    in.regionlist[5 * r + 3] = plc.regions[r].region;  // the region attribute (-A)
    in.regionlist[5 * r + 4] = -1;                     // no volume bound of its own
  }
}

// TetGen's exit codes (tetgen.h, terminatetetgen) in words.
std::string tetgen_error(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen met an internal error";
    case 3: return "TetGen found the surface self-intersecting";
    case 4: return "TetGen found an input feature too small for its tolerance";
    case 5: return "TetGen found two input facets too close";
    case 10: return "TetGen found an input error";
    default: return "TetGen stopped with code " + std::to_string(code);
  }
}

// The child's side of the pipe: raw writes, retried on interruption.
bool write_all(int fd, const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

template <class T>
bool send(int fd, const T* data, long count) {
  return write_all(fd, &count, sizeof count) && (count == 0 || write_all(fd, data, sizeof(T) * static_cast<size_t>(count)));
}

// In the child: run TetGen, send its exit code (0: finished) and, when it
// finished, points, tetrahedra, one region per tetrahedron, faces, face
// markers; then end without running the parent's atexit handlers.
// The child's address space may grow by the memory bound (its copy of the
// caller's counts already), and SIGALRM ends it at the time bound.
void limit_child(const TetgenLimits& limits) {
  if (limits.max_memory_bytes > 0) {
    long pages = 0;
    if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
      std::fclose(statm);
    }
    const double size = static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE)) + limits.max_memory_bytes;
    struct rlimit bound {};
    if (::getrlimit(RLIMIT_AS, &bound) == 0 && (bound.rlim_cur == RLIM_INFINITY || static_cast<double>(bound.rlim_cur) > size)) {
      bound.rlim_cur = static_cast<rlim_t>(size);
      ::setrlimit(RLIMIT_AS, &bound);
    }
  }
  if (limits.max_seconds > 0) {
    std::signal(SIGALRM, SIG_DFL);
    ::alarm(static_cast<unsigned>(std::ceil(limits.max_seconds)));
  }
}

[[noreturn]] void tetgen_child(int fd, const Plc& plc, const std::string& switches, pid_t parent,
                               const TetgenLimits& limits) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the caller (an interrupt ends it)
  if (::getppid() != parent) ::_exit(1);  // the caller ended before the line above took effect
  limit_child(limits);
  // A crash ends the child plainly: handlers the caller installed (a test
  // framework's, say) are not the child's to run.
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) std::signal(sig, SIG_DFL);
  tetgenio in, out;
  fill_tetgenio(plc, in);
  std::vector<char> text(switches.begin(), switches.end());
  text.push_back('\0');
  int code = 0;
  try {
    tetrahedralize(text.data(), &in, &out);
  } catch (int c) {
    code = c;
  } catch (const std::bad_alloc&) {
    code = 1;
  }
  bool sent = write_all(fd, &code, sizeof code);
  if (code == 0 && sent) {
    std::vector<int> corners;
    std::vector<double> regions;
    if (out.numberofcorners == 4) {
      corners.assign(out.tetrahedronlist, out.tetrahedronlist + 4L * out.numberoftetrahedra);
      for (int t = 0; t < out.numberoftetrahedra; ++t)
        regions.push_back(out.numberoftetrahedronattributes > 0
                              ? out.tetrahedronattributelist[static_cast<long>(t) * out.numberoftetrahedronattributes]
                              : 0.0);
    }
    std::vector<int> markers(static_cast<size_t>(out.numberoftrifaces), 0);
    if (out.trifacemarkerlist) markers.assign(out.trifacemarkerlist, out.trifacemarkerlist + out.numberoftrifaces);
    sent = send(fd, out.pointlist, 3L * out.numberofpoints) && send(fd, corners.data(), static_cast<long>(corners.size())) &&
           send(fd, regions.data(), static_cast<long>(regions.size())) &&
           send(fd, out.trifacelist, 3L * out.numberoftrifaces) &&
           send(fd, markers.data(), static_cast<long>(markers.size()));
  }
  ::_exit(sent ? 0 : 1);
}

// The parent's reading of what the child sent.
struct Received {
  const std::vector<char>& bytes;
  size_t at = 0;
  template <class T>
  bool take(std::vector<T>& out) {
    long count = 0;
    if (bytes.size() - at < sizeof count) return false;
    std::memcpy(&count, bytes.data() + at, sizeof count);
    at += sizeof count;
    if (count < 0 || static_cast<size_t>(count) > (bytes.size() - at) / sizeof(T)) return false;
    out.resize(static_cast<size_t>(count));
    if (count > 0) std::memcpy(out.data(), bytes.data() + at, sizeof(T) * static_cast<size_t>(count));
    at += sizeof(T) * static_cast<size_t>(count);
    return true;
  }
};

std::vector<char> read_until_closed(int fd) {
  std::vector<char> bytes;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  return bytes;
}

TetgenRun unpack(const std::vector<char>& bytes) {
  TetgenRun run;
  std::vector<double> points, regions;
  std::vector<int> corners, faces, markers;
  Received r{bytes, sizeof(int)};
  if (!(r.take(points) && r.take(corners) && r.take(regions) && r.take(faces) && r.take(markers)) ||
      regions.size() * 4 != corners.size() || markers.size() * 3 != faces.size()) {
    run.error = "TetGen's output came back incomplete";
    return run;
  }
  const long n = static_cast<long>(points.size() / 3);
  auto valid = [n](int v) { return v >= 0 && v < n; };
  TetMesh& mesh = run.mesh;
  for (size_t i = 0; i + 2 < points.size(); i += 3) mesh.points.emplace_back(points[i], points[i + 1], points[i + 2]);
  for (size_t t = 0; t < regions.size(); ++t) {
    std::array<int, 4> tet{corners[4 * t], corners[4 * t + 1], corners[4 * t + 2], corners[4 * t + 3]};
    for (int v : tet)
      if (!valid(v)) run.error = "TetGen's output names a point it does not have";
    mesh.tets.push_back(tet);
    mesh.tet_region.push_back(static_cast<int>(std::lround(regions[t])));
  }
  for (size_t f = 0; f < markers.size(); ++f) {
    std::array<int, 3> face{faces[3 * f], faces[3 * f + 1], faces[3 * f + 2]};
    for (int v : face)
      if (!valid(v)) run.error = "TetGen's output names a point it does not have";
    mesh.faces.push_back(face);
    mesh.face_marker.push_back(markers[f]);
  }
  return run;
}

}  // namespace

TetgenRun run_tetgen(const Plc& plc, const std::string& switches, const TetgenLimits& limits) {
  TetgenRun run;
  int fds[2];
  if (::pipe(fds) != 0) {
    run.error = std::string("cannot start TetGen: ") + std::strerror(errno);
    return run;
  }
  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    run.error = std::string("cannot start TetGen: ") + std::strerror(errno);
    return run;
  }
  if (child == 0) {
    ::close(fds[0]);
    tetgen_child(fds[1], plc, switches, parent, limits);
  }
  ::close(fds[1]);
  const std::vector<char> bytes = read_until_closed(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  int code = -1;
  if (bytes.size() >= sizeof code) std::memcpy(&code, bytes.data(), sizeof code);
  if (code == 1 && limits.max_memory_bytes > 0)
    run.error = "TetGen ran out of the memory allowed (" + std::to_string(limits.max_memory_bytes / 1e9).substr(0, 5) +
                " GB, --max-memory)";
  else if (code > 0) run.error = tetgen_error(code);
  else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM)
    run.error = "TetGen ran past the time allowed (" + std::to_string(static_cast<long>(std::ceil(limits.max_seconds))) +
                " s, --max-seconds)";
  else if (WIFSIGNALED(status))
    run.error = "TetGen crashed (signal " + std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) +
                "), as TetGen 1.5.0 does when it stops on an error in its input";
  else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || code != 0)
    run.error = "TetGen's output could not be passed back";
  if (!run.error.empty()) return run;
  return unpack(bytes);
}

}  // namespace skinmesh::detail

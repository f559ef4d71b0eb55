// Analysis throughput on the gantry grinder (issue 3, section 8): Sobol' indices with N = 2^16
// (21 inputs, N (k+2) = 1.5 M model evaluations) at one pose, and reliability over Wang & Yuan
// 2021's 75 grid poses (dx, dy, dz grids) by every method, through the weilgen CLI as a user runs
// it: compiled (built-in) model against the numeric Eigen chain (--engine numeric). Wall time,
// model evaluations (from the --json output) and evaluations per second.
//
// Usage: weilgen_bench_analysis [path/to/weilgen] [--quick]
//   --quick: smaller numeric-chain runs (N = 2^12; 5 poses) with the same per-evaluation rates.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Timing {
  double seconds = 0;
  double evaluations = 0;
};

Timing run(const std::string& weilgen, const std::string& args, const std::string& json_path,
           bool reliability) {
  const std::string cmd = weilgen + " " + args + " --quiet --json " + json_path + " > /dev/null";
  const auto t0 = std::chrono::steady_clock::now();
  if (std::system(cmd.c_str()) != 0) {
    std::cerr << "failed: " << cmd << "\n";
    std::exit(1);
  }
  Timing t;
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ifstream in(json_path);
  const auto j = nlohmann::json::parse(in);
  if (reliability) {
    for (const auto& r : j["results"]) t.evaluations += r["evaluations"].get<double>();
  } else {
    t.evaluations = j["settings"]["evaluations"].get<double>();
  }
  return t;
}

std::string row(const std::string& what, const std::string& engine, const Timing& t) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "| %s | %s | %.2f | %.3g | %.3g |", what.c_str(), engine.c_str(),
                t.seconds, t.evaluations, t.evaluations > 0 ? t.evaluations / t.seconds : 0.0);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  std::string weilgen = "build/weilgen";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else
      weilgen = a;
  }
  const std::string tmp = "/tmp/weilgen_bench_analysis.json";
  const char* grids[3][2] = {{"dx", "X=0,Y=-1500:1500:5,Z=600:1400:5"},
                             {"dy", "X=0:1000:5,Y=0,Z=600:1400:5"},
                             {"dz", "X=0:1000:5,Y=-1500:1500:5,Z=600"}};
  std::cout
      << "| run | engine | wall s | model evaluations | evaluations/s |\n|---|---|---|---|---|\n";
  const std::string sobol = "sensitivity gantry_grinder --at X=500,Y=750,Z=1000 --method sobol ";
  std::cout << row("Sobol N=2^16, 1 pose", "built-in",
                   run(weilgen, sobol + "--samples 65536", tmp, false))
            << "\n";
  const std::string nsamples = quick ? "4096" : "65536";
  std::cout << row("Sobol N=" + nsamples + ", 1 pose", "numeric chain",
                   run(weilgen, sobol + "--samples " + nsamples + " --engine numeric", tmp, false))
            << "\n";
  for (const char* method : {"exact", "form", "is", "mc"}) {
    Timing total;
    for (const auto& g : grids) {
      const Timing t = run(weilgen,
                           std::string("reliability gantry_grinder --grid ") + g[1] +
                               " --tolerance " + g[0] + "=0.03mm --method " + method,
                           tmp, true);
      total.seconds += t.seconds;
      total.evaluations += t.evaluations;
    }
    std::cout << row(std::string("reliability 75 poses, ") + method, "built-in", total) << "\n";
  }
  for (const char* method : {"form", "is", "mc"}) {
    Timing total;
    for (const auto& g : grids) {
      std::string grid = g[1];
      if (quick) grid = std::string(g[0]) == "dx" ? "X=0,Y=-1500:1500:5,Z=600" : "";
      if (grid.empty()) continue;
      const Timing t = run(weilgen,
                           std::string("reliability gantry_grinder --engine numeric --grid ") +
                               grid + " --tolerance " + g[0] + "=0.03mm --method " + method,
                           tmp, true);
      total.seconds += t.seconds;
      total.evaluations += t.evaluations;
    }
    std::cout << row(std::string("reliability ") + (quick ? "5" : "75") + " poses, " + method,
                     "numeric chain", total)
              << "\n";
  }
  std::remove(tmp.c_str());
  return 0;
}

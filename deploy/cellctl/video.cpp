#include "deploy/cellctl/video.hpp"

#include <unistd.h>

#include <cstdlib>
#include <thread>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <nettle/base64.h>

#include "deploy/cellctl/processes.hpp"

namespace cellctl {
namespace {

namespace fs = std::filesystem;

std::string find_program(const std::vector<std::string>& names) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::vector<std::string> folders;
  for (std::string d; std::getline(dirs, d, ':');) folders.push_back(d.empty() ? "." : d);
  for (const auto& name : names) {
    if (name.find('/') != std::string::npos) {
      if (::access(name.c_str(), X_OK) == 0) return name;
      continue;
    }
    for (const auto& d : folders) {
      const fs::path candidate = fs::path(d) / name;
      if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
  }
  return "";
}

std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string tail(const std::string& text, std::size_t n = 600) {
  return text.size() <= n ? text : "…" + text.substr(text.size() - n);
}

std::string decode_base64(const std::string& text) {
  base64_decode_ctx context;
  base64_decode_init(&context);
  std::string out(BASE64_DECODE_LENGTH(text.size()), '\0');
  std::size_t length = out.size();
  if (!base64_decode_update(&context, &length, reinterpret_cast<std::uint8_t*>(out.data()), text.size(), text.data()) ||
      !base64_decode_final(&context)) {
    throw std::runtime_error("chromium gave a frame that is not base64");
  }
  out.resize(length);
  return out;
}

// Runs it to its end, at most `limit`; its exit code.
int run(const std::string& name, const std::vector<std::string>& argv, const fs::path& out, const fs::path& err,
        std::chrono::seconds limit) {
  Process p(name, argv, out.string(), err.string());
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (p.poll() < 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      p.stop();
      throw std::runtime_error(name + " took longer than " + std::to_string(limit.count()) + " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return p.poll();
}

// A folder of its own, gone with it.
struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "agile-cell-video-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("cannot make a folder in " + fs::temp_directory_path().string());
    dir = pattern;
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

}  // namespace

VideoFacts write_video(const std::string& report_html, const fs::path& file, int fps) {
  const char* chosen = std::getenv("AGILE_CELL_CHROMIUM");
  const std::string chromium = find_program(chosen ? std::vector<std::string>{chosen}
                                                   : std::vector<std::string>{"chromium", "chromium-browser", "google-chrome"});
  const std::string ffmpeg = find_program({"ffmpeg"});
  if (chromium.empty() || ffmpeg.empty()) {
    throw std::runtime_error(std::string("a video needs ") + (chromium.empty() ? "chromium" : "") +
                             (chromium.empty() && ffmpeg.empty() ? " and " : "") + (ffmpeg.empty() ? "ffmpeg" : "") +
                             " (apt-get install chromium ffmpeg)");
  }
  Scratch scratch;
  const fs::path page = scratch.dir / "report.html";
  std::ofstream(page) << report_html;

  // The page renders every frame on load and leaves them, base64 JPEGs a line each, in
  // <pre id="video-frames">, which --dump-dom prints.
  const fs::path dom = scratch.dir / "dom.html", log = scratch.dir / "chromium.log";
  run("chromium",
      {chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
       "--mute-audio", "--no-first-run", "--user-data-dir=" + (scratch.dir / "profile").string(),
       "--virtual-time-budget=60000", "--dump-dom", "file://" + page.string() + "#video=" + std::to_string(fps)},
      dom, log, std::chrono::minutes(10));
  const std::string text = read_file(dom);
  const std::string open = "<pre id=\"video-frames\">";
  const auto begin = text.rfind(open);  // the last: report.js names it too
  const auto end = begin == std::string::npos ? begin : text.find("</pre>", begin);
  if (end == std::string::npos) {
    const auto error = text.find("id=\"viewer-error\">");
    throw std::runtime_error("chromium rendered no frames" +
                             (error != std::string::npos ? ": " + text.substr(error + 18, text.find('<', error + 18) - error - 18)
                                                         : "; its log ends: " + tail(read_file(log))));
  }
  VideoFacts facts;
  std::istringstream lines(text.substr(begin + open.size(), end - begin - open.size()));
  for (std::string line; std::getline(lines, line);) {
    if (line.empty()) continue;
    char name[32];
    std::snprintf(name, sizeof name, "frame-%05d.jpg", facts.frames++);
    std::ofstream(scratch.dir / name, std::ios::binary) << decode_base64(line);
  }
  const fs::path video = scratch.dir / "video.mp4", ffmpeg_log = scratch.dir / "ffmpeg.log";
  const int code = run("ffmpeg",
                       {ffmpeg, "-nostdin", "-loglevel", "error", "-y", "-framerate", std::to_string(fps), "-i",
                        (scratch.dir / "frame-%05d.jpg").string(), "-c:v", "libx264", "-pix_fmt", "yuv420p",
                        "-movflags", "+faststart", video.string()},
                       "", ffmpeg_log, std::chrono::minutes(10));
  if (code != 0) throw std::runtime_error("ffmpeg failed (exit " + std::to_string(code) + "): " + tail(read_file(ffmpeg_log)));
  fs::copy_file(video, file, fs::copy_options::overwrite_existing);
  facts.seconds = static_cast<double>(facts.frames) / fps;
  return facts;
}

}  // namespace cellctl

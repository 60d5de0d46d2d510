// cellctl plan --video as a designer gets it: the MP4 plays (ffprobe decodes every frame: as
// many, and as long, as cellctl says; H.264), and the picture changes over time. Exit 0: all
// good; 1: a check failed; 77: no chromium or ffmpeg here (ctest shows the test as skipped).
// Usage: node check_video.js CELLCTL PRODUCT.aml OUT.mp4
"use strict";
const { spawnSync } = require("child_process");
const fs = require("fs");

const [cellctl, product, out] = process.argv.slice(2);
const have = (program) => spawnSync("sh", ["-c", "command -v " + program]).status === 0;
if (!have(process.env.AGILE_CELL_CHROMIUM || "chromium") || !have("ffmpeg") || !have("ffprobe")) {
  console.log("skipped: chromium, ffmpeg or ffprobe missing");
  process.exit(77);
}
const problems = [];
const made = spawnSync(cellctl, ["plan", product, "--video", out], { encoding: "utf8", timeout: 600000 });
const said = /wrote .*\((\d+) frames, ([\d.]+) s\)/.exec(made.stdout || "");
if (made.status !== 0 || !said || !fs.existsSync(out)) {
  console.log("cellctl failed (" + made.status + "): " + made.stdout + made.stderr);
  process.exit(1);
}
const frames = Number(said[1]), seconds = Number(said[2]);

const probe = spawnSync("ffprobe", ["-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
  "stream=codec_name,pix_fmt,nb_read_frames,duration,width,height", "-of", "json", out], { encoding: "utf8" });
const stream = JSON.parse(probe.stdout).streams[0];
if (stream.codec_name !== "h264") problems.push("codec " + stream.codec_name + ", not h264");
if (stream.pix_fmt !== "yuv420p") problems.push("pixel format " + stream.pix_fmt + ": most players want yuv420p");
if (Number(stream.nb_read_frames) !== frames) problems.push(stream.nb_read_frames + " frames decoded, " + frames + " written");
if (Math.abs(Number(stream.duration) - seconds) > 0.05) problems.push(stream.duration + " s long, " + seconds + " s said");
if (frames < 25) problems.push("only " + frames + " frames");

// Grey frames at a fifth, half and four fifths of the way: each pair differs.
const grab = (t) => spawnSync("ffmpeg", ["-v", "error", "-ss", String(t), "-i", out, "-frames:v", "1", "-f", "rawvideo",
  "-pix_fmt", "gray", "-"], { maxBuffer: 1 << 26 }).stdout;
const shots = [0.2, 0.5, 0.8].map((f) => grab(f * Number(stream.duration)));
const differs = (a, b) => {
  let n = 0;
  for (let i = 0; i < a.length; ++i) if (Math.abs(a[i] - b[i]) > 16) ++n;
  return n / a.length;
};
for (const [i, j] of [[0, 1], [1, 2], [0, 2]]) {
  if (shots[i].length !== Number(stream.width) * Number(stream.height)) { problems.push("a frame could not be read"); break; }
  const d = differs(shots[i], shots[j]);
  if (d < 0.005) problems.push("frames " + i + " and " + j + " differ in " + (100 * d).toFixed(2) + "% of the picture");
}
problems.forEach((p) => console.log(out + ": " + p));
console.log(out + ": " + frames + " frames, " + stream.duration + " s, " + stream.codec_name + " " + stream.width + "x" +
            stream.height + (problems.length ? "" : "; frames differ over time"));
process.exit(problems.length ? 1 : 0);

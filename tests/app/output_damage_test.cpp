// output_damage_test.cpp — issue 32's damage items: an image output is whole or not
// written at all (docs/spec/cli.md "outputs are written atomically"), in every format the
// writer offers, on a full disk, and past a format's own size limit; and no front end
// writes onto its input (docs/limits.md).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

const std::string kSaguaro = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";

// `sylva args...` with the files it may write limited to `kib` KiB (RLIMIT_FSIZE, as
// bash's `ulimit -f`) and SIGXFSZ ignored: a write past the limit fails with EFBIG, as
// one on a full disk fails with ENOSPC — a disk that fills during the write.
ProcessResult run_sylva_on_a_full_disk(int kib, const std::vector<std::string>& args) {
  std::vector<std::string> argv{"bash", "-c", "trap '' XFSZ; ulimit -f " + std::to_string(kib) + "; exec \"$0\" \"$@\"",
                                SYLVA_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_process(argv);
}

// width x height x channels of the image at `path` when it decodes to its last row.
std::string decoded_size(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return "cannot open: " + OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
    return "cannot decode: " + in->geterror();
  return std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" + std::to_string(spec.nchannels);
}

// A disk that fills while the picture is written: exit 1 naming the file, the image that
// was there before unchanged byte for byte, no temporary left. (Before: OpenImageIO's PNG
// writer reported no short write, sylva exited 0 and renamed a truncated PNG over the
// old one.)
TEST(OutputDamage, AFullDiskIsAnErrorAndTheImageBeforeStays) {
  for (const char* name : {"s.png", "s.exr", "s.tif"}) {
    SCOPED_TRACE(name);
    TempDir dir;
    const std::string out = dir.file(name);
    const std::vector<std::string> args{"render", kSaguaro, "-o", out, "--width", "320", "--height", "240",
                                        "--spp", "1", "--backend", "cpu"};
    ProcessResult first = run_sylva(args);
    ASSERT_EQ(first.exit_code, 0) << describe(first);
    const std::string before = read_file(out);
    ASSERT_GT(before.size(), 4u << 10) << "the picture must be larger than the disk's room";

    ProcessResult full = run_sylva_on_a_full_disk(2, args);
    EXPECT_EQ(full.exit_code, 1) << describe(full);
    EXPECT_NE(full.err.find(out + ": error:"), std::string::npos) << describe(full);
    EXPECT_EQ(read_file(out), before) << "the image before was damaged";
    EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{name}) << "a temporary was left behind";
  }
}

// Every format the help names writes a whole image of the size asked. (Before: .jp2 and
// .j2k renders exited 0 and left an empty file: the plugin names its codec by the file
// name's extension, which the temporary lacked.)
TEST(OutputDamage, EveryFormatWritesAnImageThatDecodesToItsLastRow) {
  TempDir dir;
  for (const char* ext : {"png", "exr", "jpg", "jp2", "j2k", "tif", "hdr", "bmp", "tga", "webp"}) {
    SCOPED_TRACE(ext);
    const std::string out = dir.file(std::string("s.") + ext);
    ProcessResult r = run_sylva({"render", kSaguaro, "-o", out, "--width", "64", "--height", "48", "--spp", "1",
                                 "--backend", "cpu"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    const std::string size = decoded_size(out);
    EXPECT_TRUE(size == "64x48x4" || size == "64x48x3") << size;
  }
}

// A JPEG wider than libjpeg's 65,500 pixels: refused before the render with a
// `file: error:` line and nothing written. (Before: libjpeg's default error handler
// printed its own text and called exit(), leaving the temporary behind.)
TEST(OutputDamage, AnImageBeyondItsFormatsSideLimitIsRefusedBeforeTheRender) {
  for (const char* name : {"wide.jpg", "wide.webp"}) {
    SCOPED_TRACE(name);
    TempDir dir;
    const std::string out = dir.file(name);
    ProcessResult r = run_sylva({"render", kSaguaro, "-o", out, "--width", "65536", "--height", "1", "--spp", "1",
                                 "--backend", "cpu"});
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.err.find(out + ": error: a "), std::string::npos) << describe(r);
    EXPECT_NE(r.err.find("pixels a side"), std::string::npos) << describe(r);
    EXPECT_TRUE(list_dir(dir.path()).empty()) << "something was written";
  }
}

// SIGTERM (or SIGINT) to sylva while ffmpeg encodes --video: ffmpeg is stopped and reaped
// with sylva, the video's temporary is removed, and sylva ends as the signal says (143 or
// 130). An ffmpeg that takes its time stands in for a long encode: a script on PATH that
// records its pid and sleeps. (Before: SIGTERM left an orphaned ffmpeg writing the
// temporary after sylva died; Ctrl-C gave exit 1, "ffmpeg failed (exit 130)".)
TEST(OutputDamage, ASignalDuringTheVideoStopsFfmpegAndLeavesNoTemporary) {
  for (const char* signal : {"TERM", "INT"}) {
    SCOPED_TRACE(signal);
    TempDir dir;
    std::filesystem::create_directory(dir.path() / "bin");
    const std::string fake = dir.write("bin/ffmpeg", "#!/bin/sh\necho $$ > \"$(dirname \"$0\")/pid\"\nexec sleep 120\n");
    std::filesystem::permissions(fake, std::filesystem::perms::owner_all);
    // Waits for the fake ffmpeg to start, signals sylva alone (not its process group),
    // and reports sylva's status and whether the fake ffmpeg outlived it.
    const std::string script =
        "PATH=\"$1/bin:$PATH\" \"$0\" render \"$2\" --frames 0..1 -o \"$1/out/f_{frame}.png\" --video \"$1/out/v.mp4\" "
        "--width 32 --height 24 --spp 1 --backend cpu 2>\"$1/err\" & sylva=$!\n"
        "for _ in $(seq 600); do [ -s \"$1/bin/pid\" ] && break; sleep 0.1; done\n"
        "kill -" + std::string(signal) + " $sylva; wait $sylva; echo \"status $?\"\n"
        "sleep 0.5; if kill -0 \"$(cat \"$1/bin/pid\")\" 2>/dev/null; then echo orphan; kill \"$(cat \"$1/bin/pid\")\"; fi\n";
    ProcessResult r = run_process({"bash", "-c", script, SYLVA_BINARY, dir.path().string(), kSaguaro});
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find(std::string("status ") + (std::string(signal) == "TERM" ? "143" : "130")), std::string::npos)
        << describe(r) << read_file(dir.file("err"));
    EXPECT_EQ(r.out.find("orphan"), std::string::npos) << "ffmpeg outlived sylva\n" << describe(r);
    EXPECT_EQ(list_dir(dir.path() / "out"), (std::vector<std::string>{"f_0000.png", "f_0001.png"}))
        << "the frames stay; no video, no temporary";
  }
}

// Ctrl-C while a grammar derives (issue 32, item 12): the derivation polls render's SIGINT
// flag, so render stops within a step, says so and writes nothing, with status 130. The
// grammar derives ~10^6 modules for 100,000 steps — hours. (Before: the derivation ran
// to its end before the render saw the flag.) SIGINT is sent once sylva has spent two
// CPU-seconds (it is deriving by then, render's handler set: a fixed second was not always
// enough for an ASan build on a loaded machine, whose start-up a SIGINT then ended silently
// through the temporaries' handler), and again until sylva ends.
TEST(OutputDamage, CtrlCWhileTheGrammarDerivesStopsTheRenderWithinAStep) {
  TempDir dir;
  const std::string grammar = dir.write("long.lsys",
                                        "derivation length: 100000\naxiom: A(0)\nproductions:\n"
                                        "p1: A(n) : n < 20 -> A(n+1)A(n+1)\np2: A(n) : n >= 20 -> A(n)\n");
  const std::string script =
      "\"$0\" render \"$1/long.lsys\" -o \"$1/x.png\" --width 32 --height 24 --spp 1 --backend cpu 2>\"$1/err\" & "
      "sylva=$!\nticks=$((2 * $(getconf CLK_TCK)))\n"
      "for _ in $(seq 1200); do t=$(awk '{print $14 + $15}' /proc/$sylva/stat 2>/dev/null || echo 0); "
      "[ \"$t\" -ge \"$ticks\" ] && break; sleep 0.1; done\n"
      "while kill -INT $sylva 2>/dev/null; do sleep 0.5; done\nwait $sylva; echo \"status $?\"\n";
  ProcessResult r = run_process({"bash", "-c", script, SYLVA_BINARY, dir.path().string()});
  const std::string err = read_file(dir.file("err"));
  EXPECT_NE(r.out.find("status 130"), std::string::npos) << describe(r) << err;
  EXPECT_NE(err.find("sylva render: interrupted while growing; nothing written"), std::string::npos) << err;
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"err", "long.lsys"}));
}

}  // namespace

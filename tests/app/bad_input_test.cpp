// SPEC §7 end to end: the real rastray binary, run on every malformed file
// in tests/data/malformed and on bad command lines, exits with status 2 and
// prints exactly one line on stderr that starts with the file and names the
// offending element. A crash (status -1 from runRastray), a sanitizer report
// (status 1 and many lines) or a second line fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "run_command.h"

namespace {

namespace fs = std::filesystem;
using rastray::test::CommandResult;
using rastray::test::runRastray;

const std::string kMalformed = std::string(RASTRAY_TEST_DATA) + "/malformed";
const std::string kScene = std::string(RASTRAY_SCENES) + "/three-triangles.gltf";

// Exit status 2 and exactly one non-empty line ending in '\n'.
void expectOneLineStatus2(const CommandResult& r) {
  EXPECT_EQ(r.status, 2) << "stderr: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr: " << r.err;
  EXPECT_FALSE(r.err.empty() || r.err.back() != '\n') << "stderr: " << r.err;
  EXPECT_GT(r.err.size(), 1u);
}

// A malformed file and what its message must start with after "FILE: ":
// the element (empty only for problems with the file as a whole) and,
// where it pins the case down, the start of the message.
struct BadInput {
  const char* file;
  const char* expected;
};

const BadInput kBadInputs[] = {
    // JSON and document.
    {"invalid-json.gltf", "node 0: invalid JSON at line 1, column 41"},
    {"empty-file.gltf", "invalid JSON at line 1"},
    {"top-level-array.gltf", "the document must be a JSON object, got an array"},
    {"deep-nesting.gltf", "extras: JSON nesting is deeper than"},
    {"asset-missing.gltf", "asset: is missing"},
    {"asset-version-1.gltf", "asset: version \"1.0\""},
    {"extension-required-unsupported.gltf",
     "extensionsRequired: KHR_texture_basisu is required but not supported"},
    {"draco-stream-corrupt.gltf",
     "mesh 0 primitive 0 KHR_draco_mesh_compression: Draco stream does not decode"},
    {"meshopt-stream-corrupt.gltf", "bufferView 0: meshopt vertex stream does not decode"},
    {"meshopt-fallback-plain-view.gltf", "bufferView 0: refers to fallback buffer 1 without a meshopt"},
    // Wrong types.
    {"accessor-count-string.gltf", "accessor 0: \"count\" must be an integer"},
    {"node-children-number.gltf", "node 1: \"children\" must be an array"},
    {"node-matrix-string.gltf", "node 0: \"matrix\"[13] must be a number"},
    {"material-doublesided-string.gltf", "material 0: \"doubleSided\" must be a boolean"},
    {"scene-string.gltf", "scene: \"scene\" must be an integer"},
    {"node-name-number.gltf", "node 0: \"name\" must be a string"},
    {"material-name-array.gltf", "material 0: \"name\" must be a string"},
    {"light-name-object.gltf", "light 0: \"name\" must be a string"},
    {"camera-type-newline.gltf", "camera 0: \"type\""},
    // Buffers and byte ranges.
    {"buffer-missing-file.gltf", "buffer 0: "},
    {"buffer-short-data-uri.gltf", "buffer 0: data URI"},
    {"buffer-short-external.gltf", "buffer 0: "},
    {"buffer-bad-base64.gltf", "buffer 0: data URI"},
    {"buffer-uri-directory.gltf", "buffer 0: "},
    {"buffer-data-uri-media-type.gltf", "buffer 0: data URI"},
    {"bufferview-outside-buffer.gltf", "bufferView 2: bytes [96, 112) lie outside buffer 0"},
    {"accessor-count-too-large.gltf", "accessor 0: 5 elements"},
    {"accessor-offset-too-large.gltf", "accessor 1: 4 elements from byte 4"},
    {"accessor-stride-too-large.gltf", "accessor 0: 4 elements"},
    {"accessor-stride-too-small.gltf", "accessor 0: bufferView 0 byteStride 8"},
    {"accessor-component-type.gltf", "accessor 0: \"componentType\" 5124"},
    {"accessor-huge-count.gltf", "accessor 0: \"count\" 4294967296 is too large"},
    // Data.
    {"index-out-of-range.gltf", "accessor 3: index 70000 out of range (24 vertices)"},
    {"position-nan.gltf", "mesh 0 primitive 0 POSITION (accessor 0): element 1 component 0 is NaN"},
    {"position-inf.gltf", "mesh 0 primitive 0 POSITION (accessor 0): element 1 component 2 is inf"},
    {"position-float-overflow.gltf", "mesh 0 primitive 0 POSITION (accessor 0): vertex 1"},
    {"position-vec2.gltf", "mesh 0 primitive 0 POSITION (accessor 0): type VEC2"},
    {"indices-float.gltf", "mesh 0 primitive 0 indices (accessor 2): index componentType 5126"},
    {"sparse-index-out-of-range.gltf", "mesh 0 primitive 0 POSITION (accessor 0): sparse index 7"},
    {"triangles-5-indices.gltf", "mesh 0 primitive 0: 5 indices for TRIANGLES"},
    {"triangles-7-indices.gltf", "mesh 0 primitive 0: 7 indices for TRIANGLES"},
    {"normal-count-mismatch.gltf", "mesh 0 primitive 0: NORMAL has 3 elements, POSITION 4"},
    {"tangent-nan.gltf", "mesh 0 primitive 0 TANGENT (accessor 3): element 2 component 1 is NaN"},
    {"tangent-vec3.gltf", "mesh 0 primitive 0 TANGENT (accessor 3): type VEC3 is not allowed here"},
    {"tangent-count.gltf", "mesh 0 primitive 0 TANGENT (accessor 3): has 3 elements, POSITION 4"},
    {"node-matrix-overflow.gltf", "node 0: invalid JSON at line 30"},
    {"node-world-matrix-overflow.gltf", "node 1: world matrix is not finite"},
    {"node-rotation-zero.gltf", "node 0: \"rotation\" is a zero quaternion"},
    // Animations, skins, morph targets: refused whether or not --time plays them.
    {"animation-times-not-increasing.gltf", "animation 0 sampler 0: input times not increasing at key 2"},
    {"animation-output-too-short.gltf",
     "animation 0 sampler 0: output too short: 2 values for 3 input keys (3 needed)"},
    {"animation-keyframe-nan.gltf",
     "animation 0 sampler 0 output (accessor 4): element 1 component 0 is NaN"},
    {"animation-interpolation-bad.gltf",
     "animation 0 sampler 0: \"interpolation\" \"SMOOTH\" is not STEP, LINEAR or CUBICSPLINE"},
    {"animation-channel-node-missing.gltf",
     "animation 0 channel 0 target: \"node\" refers to node 5, which does not exist (1 nodes)"},
    {"animation-rotation-zero-key.gltf", "animation 0 sampler 0: output key 1 is a zero quaternion"},
    {"skin-no-joints.gltf", "skin 0: has no joints"},
    {"skin-joint-out-of-range.gltf",
     "mesh 0 primitive 0 JOINTS_0 (accessor 2): vertex 3 names joint 1; skin 0 has 1 joints"},
    {"morph-weights-count.gltf", "mesh 0: node 0 \"weights\" has 2 entries for 1 morph targets"},
    // Node graph and scenes.
    {"node-cycle.gltf", "node 0: is its own ancestor"},
    {"node-cycle-unreachable.gltf", "node 1: is its own ancestor"},
    {"node-self-child.gltf", "node 0: lists itself as a child"},
    {"node-two-parents.gltf", "node 2: is a child of both node 0 and node 1"},
    {"scene-index-missing.gltf", "scene: scene 5 does not exist"},
    {"scene-node-out-of-range.gltf", "scene 0: \"nodes\"[1] is not a node index"},
    {"scene-node-not-root.gltf", "scene 0: node 1 is not a root node"},
    {"scene-node-twice.gltf", "scene 0: lists node 0 twice"},
    // GLB containers.
    {"glb-truncated-header.glb", "GLB header: file is too short (16 bytes)"},
    {"glb-wrong-length.glb", "GLB header: declares"},
    {"glb-version-1.glb", "GLB header: version 1"},
    {"glb-json-chunk-past-eof.glb", "GLB chunk 0: length"},
    {"glb-json-chunk-unaligned.glb", "GLB chunk 0: length 83 is not a multiple of 4"},
    {"glb-bin-chunk-past-eof.glb", "GLB chunk 1: length"},
    {"glb-bin-chunk-wrong-type.glb", "GLB chunk 1: is not a BIN chunk"},
    {"glb-trailing-bytes.glb", "GLB chunk 1: header is truncated"},
    {"glb-buffer-exceeds-bin.glb", "buffer 0: byteLength 112 exceeds the GLB BIN chunk"},
    // Images and textures.
    {"image-garbage-png.gltf", "image 0: "},
    {"image-missing-file.gltf", "image 0: \"does-not-exist.png\""},
    {"image-undecodable-file.gltf", "image 0: "},
    {"image-uri-directory.gltf", "image 0: \"valid\" could not be read"},
    {"texture-source-missing.gltf", "texture 0: \"source\" refers to image 3"},
    {"normal-texture-missing.gltf", "material 0 normalTexture: \"index\" refers to texture 2"},
    {"material-texture-missing.gltf",
     "material 0 pbrMetallicRoughness baseColorTexture: \"index\" refers to texture 1"},
    // Cameras and lights.
    {"camera-znear-zero.gltf", "camera 0 perspective: \"znear\""},
    {"camera-zfar-below-znear.gltf", "camera 0 perspective: \"zfar\""},
    {"camera-node-singular.gltf", "node 1: the camera's world matrix is singular"},
    {"light-negative-intensity.gltf", "light 0: \"intensity\""},
    {"light-intensity-overflow.gltf", "light 0: \"intensity\" 1e+300 is out of float range"},
    {"material-alphacutoff-overflow.gltf", "material 0: \"alphaCutoff\" 1e+39 is out of float range"},
    {"material-ior-overflow.gltf", "material 0 KHR_materials_ior: \"ior\" 3.5e+38 is out of float range"},
    {"light-index-missing.gltf", "node 0 KHR_lights_punctual: \"light\" refers to light 0"},
    // References to elements that do not exist.
    {"mesh-index-missing.gltf", "node 0: \"mesh\" refers to mesh 5"},
    {"material-index-missing.gltf", "mesh 0 primitive 0: \"material\" refers to material 2"},
    {"accessor-index-missing.gltf", "mesh 0 primitive 0 attributes: \"NORMAL\" refers to accessor 9"},
};

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.file; }

class BadInputFile : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputFile, ExitsWithStatus2AndOneLineNamingFileAndElement) {
  const std::string path = kMalformed + "/" + GetParam().file;
  ASSERT_TRUE(fs::is_regular_file(path)) << path << " (run tests/data/malformed/generate.py)";
  const CommandResult r = runRastray({"info", path});
  expectOneLineStatus2(r);
  const std::string prefix = path + ": " + GetParam().expected;
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u)
      << "expected a line starting with\n  " << prefix << "\ngot\n  " << r.err;
}

std::string testName(const ::testing::TestParamInfo<BadInput>& info) {
  std::string name = info.param.file;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Malformed, BadInputFile, ::testing::ValuesIn(kBadInputs), testName);

// Every malformed file the generator writes has an expectation above.
TEST(BadInputTable, CoversEveryMalformedFile) {
  std::set<std::string> listed;
  for (const BadInput& b : kBadInputs) EXPECT_TRUE(listed.insert(b.file).second) << b.file;
  // Side files that cases refer to; not inputs themselves.
  const std::set<std::string> helpers{"generate.py", "buffer-short-external.bin", "not-an-image.png"};
  size_t files = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(kMalformed)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (helpers.count(name)) continue;
    ++files;
    EXPECT_TRUE(listed.count(name)) << name << " has no expected message in kBadInputs";
  }
  EXPECT_EQ(files, listed.size());
}

TEST(BadInput, JsonOutputGivesTheSameError) {
  const std::string path = kMalformed + "/index-out-of-range.gltf";
  const CommandResult r = runRastray({"info", path, "--json"});
  expectOneLineStatus2(r);
  EXPECT_EQ(r.err, path + ": accessor 3: index 70000 out of range (24 vertices)\n");
}

// The harness itself: a good scene exits 0 and prints nothing on stderr.
TEST(BadInput, ValidSceneExitsZeroSilently) {
  const CommandResult r = runRastray({"info", kScene});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

TEST(BadCommandLine, UnknownOption) {
  const CommandResult r = runRastray({"info", kScene, "--bogus"});
  expectOneLineStatus2(r);
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
}

TEST(BadCommandLine, MissingSceneArgument) {
  const CommandResult r = runRastray({"info"});
  expectOneLineStatus2(r);
  EXPECT_NE(r.err.find("scene"), std::string::npos) << r.err;
}

TEST(BadCommandLine, MissingSubcommand) {
  const CommandResult r = runRastray({});
  expectOneLineStatus2(r);
}

TEST(BadCommandLine, NonexistentFile) {
  const std::string path = kMalformed + "/no-such-file.gltf";
  const CommandResult r = runRastray({"info", path});
  expectOneLineStatus2(r);
  EXPECT_EQ(r.err.rfind(path + ": ", 0), 0u) << r.err;
}

TEST(BadCommandLine, Directory) {
  const CommandResult r = runRastray({"info", kMalformed});
  expectOneLineStatus2(r);
  EXPECT_EQ(r.err.rfind(kMalformed + ": ", 0), 0u) << r.err;
}

TEST(BadCommandLine, FileNameWithLineBreakStaysOneLine) {
  const std::string path = kMalformed + "/no\nsuch.gltf";
  const CommandResult r = runRastray({"info", path});
  expectOneLineStatus2(r);
  EXPECT_EQ(r.err.rfind(kMalformed + "/no\\x0Asuch.gltf: ", 0), 0u) << r.err;
}

TEST(BadCommandLine, ZeroWidth) {
  const CommandResult r = runRastray({"info", kScene, "--size", "0", "10"});
  expectOneLineStatus2(r);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
}

TEST(BadCommandLine, HugeWidth) {
  const CommandResult r = runRastray({"info", kScene, "--size", "100000", "100"});
  expectOneLineStatus2(r);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
}

TEST(BadCommandLine, SizeWithOneValue) {
  const CommandResult r = runRastray({"info", kScene, "--size", "10"});
  expectOneLineStatus2(r);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
}

TEST(BadCommandLine, ImpossibleCameraOverride) {
  const CommandResult r = runRastray({"info", kScene, "--eye", "0", "0", "0", "--target", "0", "0", "0"});
  expectOneLineStatus2(r);
  EXPECT_EQ(r.err.rfind("command line: --target: ", 0), 0u) << r.err;
}

}  // namespace

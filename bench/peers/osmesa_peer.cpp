// rastray_osmesa_peer: the OpenGL peer of `rastray bench --peers`. Renders
// rastray's own flattened scene (common/gltf/loader.h, rebased like
// rastray rebases it) through OSMesa, i.e. Mesa's llvmpipe on the CPU,
// with the camera given explicitly on the command line, and times frames.
//
// The work of one frame matches what rastray's rasterizer produces:
// - reversed-Z: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), a 32-bit float
//   depth buffer cleared to 0, GL_GREATER; the stored depth is the same
//   s = n/d (n(f − d)/(d(f − n)) for a finite far plane) as
//   common/depth_formula.h's reversed window depth;
// - two colour attachments: the eye-light colour (base colour factor ×
//   the diffuse weight (1 − w)(1 − t) × |n·d| + emissive, common/shading.h
//   without textures or COLOR_0) in RGBA8 (linear, the plain 8-bit target
//   an application draws into; an sRGB8_ALPHA8 target measured ~10 %
//   slower), and the IDs (instance from a per-draw uniform, triangle =
//   gl_PrimitiveID) in RG32UI;
// - MSAA with --spp samples per pixel, resolved with glBlitFramebuffer
//   (colour averaged, IDs and depth from one sample);
// - the resolved colour, IDs and depth read back with glReadPixels, as
//   rastray's frame ends with those buffers in memory (--no-readback
//   leaves this out and ends the frame with glFinish).
// Geometry is uploaded once into buffer objects before timing. One draw
// call per instance; every material is drawn opaque (no MASK or BLEND).
//
// Output (stdout): renderer, threads, scene and upload lines, "frame I: T
// ms (cpu C ms)" per timed frame (C: the CPU time of all the process's
// threads), "median cpu: C ms" and last "median frame: M ms". Exit status 0; 2 for
// bad input (one line on stderr); 1 when OpenGL fails.
#include <GL/osmesa.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/peers/peer_common.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/image.h"
#include "common/scene.h"

namespace rastray::peers {

namespace {

// OpenGL entry points past 1.1, fetched with OSMesaGetProcAddress (libOSMesa
// does not export every one of them, e.g. glClipControl).
#define RASTRAY_GL_FUNCTIONS(X)                                              \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                               \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                               \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)               \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                 \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                             \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                             \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample) \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                       \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                   \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                                 \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                               \
  X(PFNGLCLIPCONTROLPROC, ClipControl)                                       \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                         \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                         \
  X(PFNGLBUFFERDATAPROC, BufferData)                                         \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                               \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                               \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                       \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)               \
  X(PFNGLCREATESHADERPROC, CreateShader)                                     \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                     \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                   \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                       \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                             \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                   \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                     \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                       \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                     \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                           \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                         \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                         \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                         \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                           \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                         \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)

struct GlApi {
#define RASTRAY_GL_MEMBER(type, name) type name = nullptr;
  RASTRAY_GL_FUNCTIONS(RASTRAY_GL_MEMBER)
#undef RASTRAY_GL_MEMBER

  void load() {
#define RASTRAY_GL_LOAD(type, name)                                \
  name = reinterpret_cast<type>(OSMesaGetProcAddress("gl" #name)); \
  if (!name) throw std::runtime_error("OpenGL function gl" #name " is missing (Mesa too old?)");
    RASTRAY_GL_FUNCTIONS(RASTRAY_GL_LOAD)
#undef RASTRAY_GL_LOAD
  }
};

void checkGl(const char* where) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "OpenGL error 0x%04X in %s", e, where);
    throw std::runtime_error(buf);
  }
}

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 clipFromWorld;
out vec3 worldPosition;
out vec3 worldNormal;
void main() {
  worldPosition = position;
  worldNormal = normal;
  gl_Position = clipFromWorld * vec4(position, 1.0);
}
)";

// The eye light of common/shading.cpp: albedo · |n·d|. Instances without
// authored normals store (0, 0, 0), which interpolates to exactly 0: they
// take the face normal from the position's screen derivatives.
const char* kFragmentShader = R"(#version 330 core
in vec3 worldPosition;
in vec3 worldNormal;
uniform vec3 eye;
uniform vec3 viewForward;
uniform int orthographic;
uniform vec3 albedo;
uniform vec3 emission;
uniform uint instanceId;
layout(location = 0) out vec4 color;
layout(location = 1) out uvec2 ids;
void main() {
  vec3 n = worldNormal;
  if (dot(n, n) == 0.0) n = cross(dFdx(worldPosition), dFdy(worldPosition));
  vec3 d = orthographic != 0 ? viewForward : worldPosition - eye;
  color = vec4(albedo * abs(dot(normalize(n), normalize(d))) + emission, 1.0);
  ids = uvec2(instanceId, uint(gl_PrimitiveID));
}
)";

GLuint compileShader(const GlApi& gl, GLenum kind, const char* source) {
  const GLuint shader = gl.CreateShader(kind);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader compilation failed: ") + log);
  }
  return shader;
}

GLuint linkProgram(const GlApi& gl) {
  const GLuint program = gl.CreateProgram();
  gl.AttachShader(program, compileShader(gl, GL_VERTEX_SHADER, kVertexShader));
  gl.AttachShader(program, compileShader(gl, GL_FRAGMENT_SHADER, kFragmentShader));
  gl.LinkProgram(program);
  GLint ok = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetProgramInfoLog(program, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("program link failed: ") + log);
  }
  return program;
}

// Clip from view for reversed-Z with a [0, 1] clip range: window depth
// z_clip / w_clip is the reversed window depth s of common/depth_formula.h
// (n/d, n(f − d)/(d(f − n)), or (f − d)/(f − n) orthographic; d = −z_view).
// x and y follow Camera::ndcScale. Column-major, as glm and OpenGL store it.
glm::dmat4 clipFromView(const Camera& camera) {
  const glm::dvec2 scale = camera.ndcScale();
  const double n = camera.znear, f = camera.zfar;
  glm::dmat4 m(0.0);
  m[0][0] = 1.0 / scale.x;
  m[1][1] = 1.0 / scale.y;
  if (camera.projection == Projection::Orthographic) {
    m[2][2] = 1.0 / (f - n);  // s = (f + z_view) / (f − n)
    m[3][2] = f / (f - n);
    m[3][3] = 1.0;
  } else {
    m[2][3] = -1.0;  // w_clip = d
    if (std::isinf(f)) {
      m[3][2] = n;  // z_clip = n, s = n / d
    } else {
      m[2][2] = n / (f - n);  // z_clip = n(f + z_view) / (f − n)
      m[3][2] = n * f / (f - n);
    }
  }
  return m;
}

// View depth d from the stored reversed depth s (the inverse of the forms
// above); +inf where nothing was drawn.
float viewDepthOf(const Camera& camera, float stored, bool hit) {
  if (!hit) return std::numeric_limits<float>::infinity();
  const double s = stored, n = camera.znear, f = camera.zfar;
  if (camera.projection == Projection::Orthographic) return float(f - s * (f - n));
  if (std::isinf(f)) return float(n / s);
  return float(n * f / (s * (f - n) + n));
}

struct Options {
  std::string scenePath;
  PeerCameraArgs camera;
  int spp = 1;
  int frames = 10;
  int threads = 0;  // 0: leave LP_NUM_THREADS as the environment has it
  std::string out;
  bool noReadback = false;
};

// The framebuffers of one frame: `draw` is rendered into (multisampled when
// spp > 1); `resolved` holds the single-sample result (the same FBO at 1
// spp).
struct Targets {
  GLuint draw = 0, resolved = 0;
};

GLuint makeRenderbuffer(const GlApi& gl, int samples, GLenum format, int w, int h) {
  GLuint rb = 0;
  gl.GenRenderbuffers(1, &rb);
  gl.BindRenderbuffer(GL_RENDERBUFFER, rb);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
  checkGl("renderbuffer storage");
  return rb;
}

GLuint makeFramebuffer(const GlApi& gl, int samples, int w, int h) {
  GLuint fbo = 0;
  gl.GenFramebuffers(1, &fbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                             makeRenderbuffer(gl, samples, GL_RGBA8, w, h));
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER,
                             makeRenderbuffer(gl, samples, GL_RG32UI, w, h));
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                             makeRenderbuffer(gl, samples, GL_DEPTH_COMPONENT32F, w, h));
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "framebuffer with %d samples incomplete (status 0x%04X)", samples, status);
    throw std::runtime_error(buf);
  }
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, both);
  return fbo;
}

struct InstanceDraw {
  uint32_t instance = 0;
  GLsizei indexCount = 0;
  size_t indexOffsetBytes = 0;
  glm::vec3 albedo{0.0f}, emission{0.0f};
};

struct Readback {
  std::vector<uint8_t> color;  // linear RGBA8, bottom row first
  std::vector<uint32_t> ids;   // (instance, triangle) pairs
  std::vector<float> depth;    // stored reversed depth s
};

int run(const Options& o) {
  if (o.spp < 1) throw InputError("command line", "--spp", "must be at least 1");
  if (o.frames < 1) throw InputError("command line", "--frames", "must be at least 1");
  if (o.threads < 0) throw InputError("command line", "--threads", "must be >= 0");
  Scene scene = loadScene(o.scenePath);
  const Camera camera = resolveCamera(scene, o.camera);
  const int w = camera.width, h = camera.height;

  // llvmpipe reads LP_NUM_THREADS when its screen is created, i.e. with
  // the first context.
  if (o.threads > 0) setenv("LP_NUM_THREADS", std::to_string(o.threads).c_str(), 1);
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         4,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         5,
                         0};
  OSMesaContext context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!context) throw std::runtime_error("OSMesa could not create an OpenGL 4.5 core context");
  // OSMesa needs a bound buffer; everything is drawn into our framebuffers.
  std::vector<uint8_t> dummy(4);
  if (!OSMesaMakeCurrent(context, dummy.data(), GL_UNSIGNED_BYTE, 1, 1))
    throw std::runtime_error("OSMesaMakeCurrent failed");
  GlApi gl;
  gl.load();
  const char* lpThreads = std::getenv("LP_NUM_THREADS");
  std::printf("renderer: %s | %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
              reinterpret_cast<const char*>(glGetString(GL_VERSION)));
  std::printf("threads: LP_NUM_THREADS=%s\n", lpThreads ? lpThreads : "(unset: one per core)");

  GLint maxSamples = 0, maxIntegerSamples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  glGetIntegerv(GL_MAX_INTEGER_SAMPLES, &maxIntegerSamples);
  if (o.spp > 1 && (o.spp > maxSamples || o.spp > maxIntegerSamples))
    throw InputError("command line", "--spp",
                     std::to_string(o.spp) + " samples: this OpenGL supports at most " +
                         std::to_string(std::min(maxSamples, maxIntegerSamples)));

  // ---- Upload (not timed as a frame).
  const auto uploadStart = std::chrono::steady_clock::now();
  GLuint vao = 0, buffers[3] = {};
  gl.GenVertexArrays(1, &vao);
  gl.BindVertexArray(vao);
  gl.GenBuffers(3, buffers);
  gl.BindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(scene.positions.size() * sizeof(glm::vec3)),
                scene.positions.data(), GL_STATIC_DRAW);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  gl.EnableVertexAttribArray(0);
  gl.BindBuffer(GL_ARRAY_BUFFER, buffers[1]);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(scene.normals.size() * sizeof(glm::vec3)), scene.normals.data(),
                GL_STATIC_DRAW);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  gl.EnableVertexAttribArray(1);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[2]);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(scene.triangles.size() * sizeof(glm::uvec3)),
                scene.triangles.data(), GL_STATIC_DRAW);
  checkGl("geometry upload");

  std::vector<InstanceDraw> draws;
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.triangleCount == 0) continue;
    const Material& m = scene.materials[inst.material];
    InstanceDraw d;
    d.instance = i;
    d.indexCount = GLsizei(3 * inst.triangleCount);
    d.indexOffsetBytes = size_t(inst.firstTriangle) * sizeof(glm::uvec3);
    // The diffuse share of common/shading.h: (1 − w)(1 − t).
    d.albedo = glm::vec3(m.baseColorFactor) * ((1.0f - m.mirrorWeight()) * (1.0f - m.transmission));
    d.emission = m.emissive;
    draws.push_back(d);
  }

  const GLuint program = linkProgram(gl);
  gl.UseProgram(program);
  const glm::mat4 clipFromWorld(clipFromView(camera) * camera.viewFromWorld);
  gl.UniformMatrix4fv(gl.GetUniformLocation(program, "clipFromWorld"), 1, GL_FALSE, &clipFromWorld[0][0]);
  const glm::vec3 eye(camera.eye()), forward(camera.forward());
  gl.Uniform3fv(gl.GetUniformLocation(program, "eye"), 1, &eye[0]);
  gl.Uniform3fv(gl.GetUniformLocation(program, "viewForward"), 1, &forward[0]);
  gl.Uniform1i(gl.GetUniformLocation(program, "orthographic"), camera.projection == Projection::Orthographic);
  const GLint albedoLoc = gl.GetUniformLocation(program, "albedo");
  const GLint emissionLoc = gl.GetUniformLocation(program, "emission");
  const GLint instanceLoc = gl.GetUniformLocation(program, "instanceId");

  Targets targets;
  targets.resolved = makeFramebuffer(gl, 0, w, h);
  targets.draw = o.spp > 1 ? makeFramebuffer(gl, o.spp, w, h) : targets.resolved;
  gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDisable(GL_CULL_FACE);  // rastray's default: --cull none
  if (o.spp > 1) glEnable(GL_MULTISAMPLE);
  glViewport(0, 0, w, h);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glFinish();
  checkGl("setup");
  const double uploadMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - uploadStart).count();
  std::printf("scene: %zu instances, %zu triangles, %dx%d, %d spp\n", scene.instances.size(),
              scene.triangles.size(), w, h, o.spp);
  std::printf("upload: %.3f ms\n", uploadMs);

  Readback rb;
  rb.color.resize(size_t(w) * h * 4);
  rb.ids.resize(size_t(w) * h * 2);
  rb.depth.resize(size_t(w) * h);

  const auto readBack = [&] {
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, targets.resolved);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rb.color.data());
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    glReadPixels(0, 0, w, h, GL_RG_INTEGER, GL_UNSIGNED_INT, rb.ids.data());
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, rb.depth.data());
  };
  const auto frame = [&] {
    gl.BindFramebuffer(GL_FRAMEBUFFER, targets.draw);
    const GLfloat black[4] = {0, 0, 0, 0};
    const GLuint noIds[4] = {kNoId, kNoId, 0, 0};
    const GLfloat farDepth = 0.0f;  // reversed: 0 is infinitely far
    gl.ClearBufferfv(GL_COLOR, 0, black);
    gl.ClearBufferuiv(GL_COLOR, 1, noIds);
    gl.ClearBufferfv(GL_DEPTH, 0, &farDepth);
    for (const InstanceDraw& d : draws) {
      gl.Uniform1ui(instanceLoc, d.instance);
      gl.Uniform3fv(albedoLoc, 1, &d.albedo[0]);
      gl.Uniform3fv(emissionLoc, 1, &d.emission[0]);
      glDrawElements(GL_TRIANGLES, d.indexCount, GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(d.indexOffsetBytes));
    }
    if (targets.draw != targets.resolved) {
      // Resolve: colour (averaged) with depth, then the IDs (integer: one
      // sample's value), each to its own draw buffer.
      gl.BindFramebuffer(GL_READ_FRAMEBUFFER, targets.draw);
      gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, targets.resolved);
      const GLenum first[2] = {GL_COLOR_ATTACHMENT0, GL_NONE}, second[2] = {GL_NONE, GL_COLOR_ATTACHMENT1};
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      gl.DrawBuffers(2, first);
      gl.BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
      glReadBuffer(GL_COLOR_ATTACHMENT1);
      gl.DrawBuffers(2, second);
      gl.BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glFinish();
    if (!o.noReadback) readBack();
  };

  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  frame();
  checkGl("warm-up frame");
  std::printf("warm-up: %.3f ms\n", std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  // CPU time of every thread of the process (llvmpipe's included): on a
  // shared machine the wall time also holds other programs' turns.
  const auto cpuNowMs = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  };
  std::vector<double> frameMs, cpuMs;
  for (int i = 0; i < o.frames; ++i) {
    t0 = Clock::now();
    const double cpu0 = cpuNowMs();
    frame();
    frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    cpuMs.push_back(cpuNowMs() - cpu0);
  }
  checkGl("frames");
  printFrameTimes(frameMs, cpuMs);

  if (!o.out.empty()) {
    if (o.noReadback) readBack();  // the frames left the pixels on the GL side
    FlatImage image(w, h);
    for (int y = 0; y < h; ++y) {
      const size_t src = size_t(h - 1 - y) * w;  // OpenGL's row 0 is the bottom one
      for (int x = 0; x < w; ++x) {
        const size_t s = src + x, d = image.index(x, y);
        const uint8_t* c = &rb.color[4 * s];
        // The resolve averaged colour over transparent black: linear
        // colour with this alpha is premultiplied already.
        image.color[d] = glm::vec4(c[0], c[1], c[2], c[3]) / 255.0f;
        image.instance[d] = rb.ids[2 * s];
        image.triangle[d] = rb.ids[2 * s + 1];
        image.depth[d] = viewDepthOf(camera, rb.depth[s], image.instance[d] != kNoId);
      }
    }
    writeImage(o.out, image);
  }
  OSMesaDestroyContext(context);
  return 0;
}

}  // namespace

}  // namespace rastray::peers

int main(int argc, char** argv) {
  using namespace rastray::peers;
  Options o;
  CLI::App app{
      "rastray_osmesa_peer: times OpenGL (Mesa llvmpipe through OSMesa) on rastray's flattened scene "
      "with an explicit camera; the last line is 'median frame: <ms> ms'",
      "rastray_osmesa_peer"};
  addSceneOptions(app, o.scenePath, o.camera);
  app.add_option("--spp", o.spp, "samples per pixel (MSAA when > 1)");
  app.add_option("--frames", o.frames, "timed frames, after one warm-up frame");
  app.add_option("--threads", o.threads,
                 "llvmpipe threads (sets LP_NUM_THREADS; default: as the environment)");
  app.add_option("--out", o.out, "write the last frame (.png, or .exr with Z and IDs)");
  app.add_flag("--no-readback", o.noReadback, "end the frame at glFinish, without glReadPixels");
  return runPeerMain(app, argc, argv, [&] { return run(o); });
}

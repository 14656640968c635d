// expr.cpp — the bytecode machine for grammar expressions (see expr.h).
#include "lsystem/expr.h"

#include "core/util/file_io.h"
#include "core/util/math.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <cstring>
#include <string>

namespace sylva::lsys {

namespace {

void print_to_stderr(std::string_view text) { std::fwrite(text.data(), 1, text.size(), stderr); }
PrintSink print_sink_ = print_to_stderr;

// One conversion of a printf format: [flags][width][.precision][length]conversion.
struct Conversion {
  size_t end = 0;        // one past it
  std::string spec;      // "%-8.3" without length modifiers or the conversion
  char conversion = 0;
};

// The conversion starting at format[i] == '%' (not "%%"); conversion 0 with an error.
Conversion parse_conversion(std::string_view format, size_t i, std::string* error) {
  Conversion c;
  size_t k = i + 1;
  c.spec = "%";
  while (k < format.size() && std::strchr("-+ #0", format[k])) c.spec += format[k++];
  while (k < format.size() && format[k] >= '0' && format[k] <= '9') c.spec += format[k++];
  if (k < format.size() && format[k] == '.') {
    c.spec += format[k++];
    while (k < format.size() && format[k] >= '0' && format[k] <= '9') c.spec += format[k++];
  }
  while (k < format.size() && std::strchr("hlLqjzt", format[k])) ++k;  // a double is printed either way
  if (k >= format.size()) {
    *error = "a '%' at the end of the format";
    return c;
  }
  if (c.spec.size() > 12) {
    *error = "a conversion's width or precision is too long";
    return c;
  }
  const char conv = format[k];
  if (!std::strchr("diuoxXceEfFgG", conv)) {
    *error = conv == 's' ? "printf's %s: sylva's values are numbers, it has no strings"
                         : conv == '*' ? "printf's '*' width: give the width in the format"
                                       : std::string("printf's %") + conv + " is not a conversion sylva can print";
    return c;
  }
  c.conversion = conv;
  c.end = k + 1;
  return c;
}

// One conversion of an fscanf format: %[*][width][length]conversion (C's scanf).
struct ScanConversion {
  size_t end = 0;          // one past it
  size_t width = 0;        // 0: none
  bool suppressed = false; // %*f: read and not stored
  char conversion = 0;     // '%' for "%%"
};

// The conversion starting at format[i] == '%'; conversion 0 with an error.
ScanConversion parse_scan_conversion(std::string_view format, size_t i, std::string* error) {
  ScanConversion c;
  size_t k = i + 1;
  if (k < format.size() && format[k] == '%') {
    c.conversion = '%';
    c.end = k + 1;
    return c;
  }
  if (k < format.size() && format[k] == '*') c.suppressed = true, ++k;
  while (k < format.size() && format[k] >= '0' && format[k] <= '9') {
    c.width = c.width * 10 + static_cast<size_t>(format[k++] - '0');
    if (c.width > 4096) {
      *error = "a conversion's width is too long";
      return c;
    }
  }
  while (k < format.size() && std::strchr("lL", format[k])) ++k;  // float or double: a number either way
  if (k >= format.size()) {
    *error = "a '%' at the end of the format";
    return c;
  }
  const char conv = format[k];
  if (!std::strchr("eEfFgGaA", conv)) {
    *error = std::string("fscanf's %") + conv +
             ": every cpfg variable is a number (CPFG manual 5.4), read it with %f, %e or %g";
    return c;
  }
  c.conversion = conv;
  c.end = k + 1;
  return c;
}

bool is_c_space(char ch) { return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == '\v' || ch == '\f'; }

}  // namespace

FormatCheck check_scan_format(std::string_view format) {
  FormatCheck out;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    const ScanConversion c = parse_scan_conversion(format, i, &out.error);
    if (!c.conversion) return out;
    if (c.conversion != '%' && !c.suppressed) ++out.values;
    i = c.end - 1;
  }
  return out;
}

PrintSink set_print_sink(PrintSink sink) {
  PrintSink old = print_sink_;
  print_sink_ = sink ? sink : print_to_stderr;
  return old;
}

FormatCheck check_format(std::string_view format) {
  FormatCheck out;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    if (i + 1 < format.size() && format[i + 1] == '%') {
      ++i;
      continue;
    }
    Conversion c = parse_conversion(format, i, &out.error);
    if (!c.conversion) return out;
    ++out.values;
    i = c.end - 1;
  }
  return out;
}

std::string apply_format(std::string_view format, const double* values) {
  std::string out;
  char buffer[512];
  std::string error;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') {
      out += format[i];
      continue;
    }
    if (i + 1 < format.size() && format[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    Conversion c = parse_conversion(format, i, &error);
    if (!c.conversion) break;  // check_format refused it when it was compiled
    const double v = *values++;
    if (std::strchr("diuoxXc", c.conversion)) {
      // C converts to an integer; a value beyond one prints as the nearest one.
      const double clamped = std::isnan(v) ? 0.0 : std::clamp(v, -9.2e18, 9.2e18);
      const auto n = static_cast<long long>(clamped);
      const char conv = c.conversion == 'i' ? 'd' : c.conversion;
      const std::string f = c.spec + (conv == 'c' ? "c" : std::string("ll") + conv);
      if (conv == 'c') std::snprintf(buffer, sizeof buffer, f.c_str(), static_cast<int>(n & 0xFF));
      else std::snprintf(buffer, sizeof buffer, f.c_str(), n);
    } else {
      const std::string f = c.spec + c.conversion;
      std::snprintf(buffer, sizeof buffer, f.c_str(), v);
    }
    out += buffer;
    i = c.end - 1;
  }
  return out;
}

namespace {

const FuncInfo kFuncs[] = {
    {"sin", 1, false},   {"cos", 1, false},   {"tan", 1, false},   {"asin", 1, false},
    {"acos", 1, false},  {"atan", 1, false},  {"atan2", 2, false}, {"sqrt", 1, false},
    {"exp", 1, false},   {"log", 1, false},   {"pow", 2, false},   {"abs", 1, false},
    {"floor", 1, false}, {"ceil", 1, false},  {"min", 2, false},   {"max", 2, false},
    {"clamp", 3, false}, {"rand", 0, true},   {"uniform", 2, true}, {"gauss", 2, true},
    {"fabs", 1, false},  {"trunc", 1, false}, {"sign", 1, false},  {"ran", 1, true},
    {"nran", 2, true},   {"bran", 2, true},   {"biran", 2, true},  {"srand", 1, true},
    {"func", 2, false},  {"stop", 1, false},
    {"curveX", 2, false}, {"curveY", 2, false}, {"curveZ", 2, false}, {"curveGAL", 1, false},
    {"fflush", 1, false}, {"fclose", 1, false},
};

// The largest n biran(n, p) draws for (n uniform draws: bounded time, docs/cpfg.md).
constexpr double kMaxBiranTrials = 1e6;

// A Gamma(k, 1) variate, k > 0 (Marsaglia and Tsang 2000; k < 1 by Gamma(k + 1)·U^(1/k)).
// The rejection loop accepts with probability above 0.95 per try; it is bounded, and after
// the bound returns the mean (a run of 64 rejections has probability below 1e-80).
double gamma_variate(double k, Rng* rng) {
  double boost = 1;
  if (k < 1) {
    boost = std::pow(1.0 - rng->next_double(), 1 / k);
    k += 1;
  }
  const double d = k - 1.0 / 3.0, c = 1 / std::sqrt(9 * d);
  for (int tries = 0; tries < 64; ++tries) {
    double x, v;
    do {
      x = rng->next_gauss();
      v = 1 + c * x;
    } while (v <= 0);
    v = v * v * v;
    const double u = 1.0 - rng->next_double();
    if (std::log(u) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v * boost;
  }
  return d * boost;
}

// Reduces degrees to a quadrant q (0..3) and a remainder in [-45, 45] degrees.
void reduce_degrees(double degrees, int* quadrant, double* rem_rad) {
  double r = std::fmod(degrees, 360.0);  // exact
  if (r < 0) r += 360.0;
  double q = std::nearbyint(r / 90.0);
  *rem_rad = (r - q * 90.0) * kRadPerDeg;
  *quadrant = static_cast<int>(q) & 3;
}

// An array index as a message shows it: %g (NaN and infinities by name).
std::string index_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

[[noreturn]] void fail(SourceLoc loc, std::string message) {
  throw EvalError{loc, std::move(message)};
}
}  // namespace

// "+ 0.0" turns a -0 from the quadrant sign into +0: sin(180) prints as 0, not -0.
double sin_deg(double degrees) {
  int q;
  double a;
  reduce_degrees(degrees, &q, &a);
  switch (q) {
    case 0: return std::sin(a) + 0.0;
    case 1: return std::cos(a) + 0.0;
    case 2: return -std::sin(a) + 0.0;
    default: return -std::cos(a) + 0.0;
  }
}

double cos_deg(double degrees) {
  int q;
  double a;
  reduce_degrees(degrees, &q, &a);
  switch (q) {
    case 0: return std::cos(a) + 0.0;
    case 1: return -std::sin(a) + 0.0;
    case 2: return -std::cos(a) + 0.0;
    default: return std::sin(a) + 0.0;
  }
}

const FuncInfo& func_info(Func f) { return kFuncs[static_cast<int>(f)]; }

bool find_func(const std::string& name, Func* f) {
  for (size_t i = 0; i < std::size(kFuncs); ++i) {
    if (name == kFuncs[i].name) {
      *f = static_cast<Func>(i);
      return true;
    }
  }
  return false;
}

double Program::run(const Expr& e, double* slots, Rng* rng, EvalContext* context) const {
  // Expressions are shallow (the parser bounds nesting), so a fixed stack suffices; the
  // compiler checks the depth it needs against kMaxEvalStack.
  double stack[kMaxEvalStack];
  int sp = 0;
  uint64_t loops = 0;
  const Instr* code_ptr = code.data();
  for (uint32_t pc = e.begin; pc < e.end; ++pc) {
    const Instr& in = code_ptr[pc];
    auto check = [&](double v) {
      if (!std::isfinite(v)) fail(locs[pc], "result is not finite (NaN or infinity)");
      return v;
    };
    switch (in.op) {
      case Op::kConst: stack[sp++] = consts[in.arg]; break;
      case Op::kSlot: stack[sp++] = slots[in.arg]; break;
      case Op::kAdd: --sp; stack[sp - 1] = check(stack[sp - 1] + stack[sp]); break;
      case Op::kSub: --sp; stack[sp - 1] = check(stack[sp - 1] - stack[sp]); break;
      case Op::kMul: --sp; stack[sp - 1] = check(stack[sp - 1] * stack[sp]); break;
      case Op::kRem: {
        --sp;
        // As cpfg's Eval: both made C ints (truncated toward zero), then C's remainder.
        auto to_int = [](double v) { return std::isnan(v) ? 0LL : static_cast<long long>(std::clamp(v, -2147483648.0, 2147483647.0)); };
        const long long a = to_int(stack[sp - 1]), d = to_int(stack[sp]);
        if (d == 0) fail(locs[pc], "remainder by zero ('%' of a value whose whole part is 0)");
        stack[sp - 1] = static_cast<double>(a % d);
        break;
      }
      case Op::kDiv:
        --sp;
        if (stack[sp] == 0.0) fail(locs[pc], "division by zero");
        stack[sp - 1] = check(stack[sp - 1] / stack[sp]);
        break;
      case Op::kPow: --sp; stack[sp - 1] = check(std::pow(stack[sp - 1], stack[sp])); break;
      case Op::kNeg: stack[sp - 1] = -stack[sp - 1]; break;
      case Op::kNot: stack[sp - 1] = stack[sp - 1] == 0.0 ? 1.0 : 0.0; break;
      case Op::kLt: --sp; stack[sp - 1] = stack[sp - 1] < stack[sp]; break;
      case Op::kLe: --sp; stack[sp - 1] = stack[sp - 1] <= stack[sp]; break;
      case Op::kGt: --sp; stack[sp - 1] = stack[sp - 1] > stack[sp]; break;
      case Op::kGe: --sp; stack[sp - 1] = stack[sp - 1] >= stack[sp]; break;
      case Op::kEq: --sp; stack[sp - 1] = stack[sp - 1] == stack[sp]; break;
      case Op::kNe: --sp; stack[sp - 1] = stack[sp - 1] != stack[sp]; break;
      case Op::kAndJump:
        if (stack[--sp] == 0.0) {
          stack[sp++] = 0.0;
          pc = in.arg - 1;
        }
        break;
      case Op::kOrJump:
        if (stack[--sp] != 0.0) {
          stack[sp++] = 1.0;
          pc = in.arg - 1;
        }
        break;
      case Op::kBool: stack[sp - 1] = stack[sp - 1] != 0.0 ? 1.0 : 0.0; break;
      case Op::kStore: slots[in.arg] = stack[--sp]; break;
      case Op::kGlobal: stack[sp++] = context->globals[in.arg]; break;
      case Op::kStoreGlobal: context->globals[in.arg] = stack[--sp]; break;
      case Op::kJump: pc = in.arg - 1; break;
      case Op::kJumpIfZero:
        if (stack[--sp] == 0.0) pc = in.arg - 1;
        break;
      case Op::kLoop:
        if (++loops > kMaxLoopIterations)
          fail(locs[pc], "a loop ran more than " + std::to_string(kMaxLoopIterations) + " times (a runaway loop?)");
        pc = in.arg - 1;
        break;
      case Op::kPop: --sp; break;
      case Op::kDup: stack[sp] = stack[sp - 1]; ++sp; break;
      case Op::kFileOpen:
      case Op::kFileRead: {
        if (!context || !context->files) fail(locs[pc], "files are opened by a derivation's statements only");
        double id = 0;
        const std::string error = context->files->open(formats[in.arg], in.op == Op::kFileRead, &id);
        if (!error.empty()) fail(locs[pc], "fopen: " + error);
        stack[sp++] = id;
        break;
      }
      case Op::kFileScan: {
        if (!context || !context->files) fail(locs[pc], "files are read by a derivation's statements only");
        const Scan& scan = scans[in.arg];
        sp -= in.pad;
        std::vector<double> values(in.pad, 0.0);
        int read = 0;
        const std::string error = context->files->scan(stack[sp - 1], formats[scan.format], values, &read);
        if (!error.empty()) fail(locs[pc], "fscanf: " + error);
        for (int k = 0; k < read; ++k) {
          const auto target = static_cast<uint32_t>(stack[sp + k]);
          (scan.local[static_cast<size_t>(k)] ? slots : context->globals)[target] = values[static_cast<size_t>(k)];
        }
        stack[sp - 1] = read;
        break;
      }
      case Op::kFilePrint: {
        if (!context || !context->files) fail(locs[pc], "files are written by a derivation's statements only");
        sp -= in.pad;
        const std::string text = apply_format(formats[in.arg], stack + sp);
        const std::string error = context->files->append(stack[sp - 1], text);
        if (!error.empty()) fail(locs[pc], "fprintf: " + error);
        stack[sp - 1] = 0.0;
        break;
      }
      case Op::kPrint: {
        sp -= in.pad;
        const std::string text = apply_format(formats[in.arg], stack + sp);
        print_sink_(text);
        stack[sp++] = 0.0;
        break;
      }
      case Op::kArrayIndex: {
        const ArrayInfo& a = arrays[in.arg];
        const size_t rank = a.dims.size();
        sp -= static_cast<int>(rank);
        uint64_t flat = 0;
        for (size_t k = 0; k < rank; ++k) {
          const double v = stack[sp + static_cast<int>(k)];
          // C's conversion, as cpfg's: the index truncated toward zero.
          if (!(v > -1.0) || !(v < static_cast<double>(a.dims[k])))
            fail(locs[pc], "index " + index_text(v) + " is outside " + a.name + "'s " +
                               (rank == 1 ? std::string("0 .. ") + std::to_string(a.dims[k] - 1)
                                          : "dimension " + std::to_string(k + 1) + " (0 .. " +
                                                std::to_string(a.dims[k] - 1) + ")"));
          flat = flat * a.dims[k] + static_cast<uint64_t>(std::trunc(v));
        }
        stack[sp++] = static_cast<double>(a.base + flat);
        break;
      }
      case Op::kLoadAt: stack[sp - 1] = context->globals[static_cast<size_t>(stack[sp - 1])]; break;
      case Op::kStoreAt:
        sp -= 2;
        context->globals[static_cast<size_t>(stack[sp])] = stack[sp + 1];
        break;
      case Op::kCall: {
        double r = 0;
        double* a = nullptr;
        int arity = func_info(in.fn).arity;
        sp -= arity;
        a = stack + sp;
        switch (in.fn) {
          case Func::kSin: r = sin_deg(a[0]); break;
          case Func::kCos: r = cos_deg(a[0]); break;
          case Func::kTan: {
            double c = cos_deg(a[0]);
            if (c == 0.0) fail(locs[pc], "tan of an odd multiple of 90 degrees is not finite");
            r = sin_deg(a[0]) / c + 0.0;
            break;
          }
          case Func::kAsin: r = std::asin(a[0]) / kRadPerDeg; break;
          case Func::kAcos: r = std::acos(a[0]) / kRadPerDeg; break;
          case Func::kAtan: r = std::atan(a[0]) / kRadPerDeg; break;
          case Func::kAtan2: r = std::atan2(a[0], a[1]) / kRadPerDeg; break;
          case Func::kSqrt: r = std::sqrt(a[0]); break;
          case Func::kExp: r = std::exp(a[0]); break;
          case Func::kLog: r = std::log(a[0]); break;
          case Func::kPow: r = std::pow(a[0], a[1]); break;
          case Func::kAbs: r = std::fabs(a[0]); break;
          case Func::kFloor: r = std::floor(a[0]); break;
          case Func::kCeil: r = std::ceil(a[0]); break;
          case Func::kMin: r = std::min(a[0], a[1]); break;
          case Func::kMax: r = std::max(a[0], a[1]); break;
          case Func::kClamp:
            if (a[1] > a[2]) fail(locs[pc], "clamp(x, lo, hi) needs lo <= hi");
            r = std::clamp(a[0], a[1], a[2]);
            break;
          case Func::kRand: r = rng->next_double(); break;
          case Func::kUniform: r = a[0] + (a[1] - a[0]) * rng->next_double(); break;
          case Func::kGauss: r = a[0] + a[1] * rng->next_gauss(); break;
          case Func::kFabs: r = std::fabs(a[0]); break;
          case Func::kTrunc: r = std::trunc(a[0]); break;
          case Func::kSign: r = a[0] > 0 ? 1.0 : (a[0] < 0 ? -1.0 : 0.0); break;
          case Func::kRan: r = a[0] * rng->next_double(); break;
          case Func::kNran: r = a[0] + a[1] * rng->next_gauss(); break;
          case Func::kBran: {
            if (!(a[0] > 0) || !(a[1] > 0)) fail(locs[pc], "bran(a, b) needs a > 0 and b > 0");
            const double x = gamma_variate(a[0], rng), y = gamma_variate(a[1], rng);
            r = x + y > 0 ? x / (x + y) : 0.5;
            break;
          }
          case Func::kSrand: {
            if (!(a[0] >= 0) || a[0] != std::floor(a[0]) || a[0] > 9007199254740992.0)
              fail(locs[pc], "srand(s) needs a non-negative integer s");
            const auto seed = static_cast<uint64_t>(a[0]);
            *rng = Rng(mix_pair(seed, 0x5EEDULL));
            if (context) context->reseeded = true, context->reseed = seed;
            r = 0;
            break;
          }
          case Func::kCurveX:
          case Func::kCurveY:
          case Func::kCurveZ:
          case Func::kCurveGal: {
            // The view file's curve id, 1-based (CPFG manual 5.5): t a fraction of its length.
            if (!(a[0] >= 1) || a[0] != std::floor(a[0]) || a[0] > static_cast<double>(curves.size()))
              fail(locs[pc], std::string(func_info(in.fn).name) + "(" + index_text(a[0]) + ", ...): " +
                                 (curves.empty() ? std::string("this model has no curves (a vlab object's view file "
                                                               "names them: 'curve: file.con')")
                                                 : "the curve id is 1 to " + std::to_string(curves.size()) +
                                                       " (the view file's curve: lines, in order)"));
            const CpfgCurve& c = curves[static_cast<size_t>(a[0]) - 1];
            if (in.fn == Func::kCurveGal) {
              r = c.length;
            } else {
              r = c.at_length(a[1])[in.fn == Func::kCurveX ? 0 : in.fn == Func::kCurveY ? 1 : 2];
            }
            break;
          }
          case Func::kFflush:
          case Func::kFclose: {
            if (!context || !context->files) fail(locs[pc], "files are written by a derivation's statements only");
            const std::string error = context->files->write(a[0], in.fn == Func::kFclose);
            if (!error.empty()) fail(locs[pc], std::string(func_info(in.fn).name) + ": " + error);
            r = 0;
            break;
          }
          case Func::kStop:
            if (context) context->stop = true;
            r = 0;
            break;
          case Func::kFunc: {
            // func(id, x) (CPFG manual 5.5): the view file's function id, 1-based.
            if (!(a[0] >= 1) || a[0] != std::floor(a[0]) || a[0] > static_cast<double>(functions.size()))
              fail(locs[pc], "func(" + index_text(a[0]) + ", x): " +
                                 (functions.empty() ? std::string("this model has no functions (a vlab object's view "
                                                                  "file names them: 'function: file.func', docs/cpfg.md)")
                                                    : "the function id is 1 to " + std::to_string(functions.size()) +
                                                          " (the view file's functions, in order)"));
            r = functions[static_cast<size_t>(a[0]) - 1].value(a[1]);
            break;
          }
          case Func::kBiran: {
            if (!(a[0] >= 0) || a[0] != std::floor(a[0]) || a[0] > kMaxBiranTrials)
              fail(locs[pc], "biran(n, p) needs an integer n from 0 to 1000000");
            if (!(a[1] >= 0 && a[1] <= 1)) fail(locs[pc], "biran(n, p) needs p from 0 to 1");
            const auto n = static_cast<int64_t>(a[0]);
            int64_t hits = 0;
            for (int64_t k = 0; k < n; ++k) hits += rng->next_double() < a[1];
            r = static_cast<double>(hits);
            break;
          }
        }
        stack[sp++] = check(r);
        break;
      }
    }
  }
  return stack[sp - 1];
}

namespace {
// A file's read or write error as one line of a statement's message: "'path': what failed".
std::string failed_on(const std::string& path, const Diagnostic& d) { return "'" + path + "': " + d.message; }
}  // namespace

std::string ModelFiles::open(const std::string& name, bool reading, double* id) {
  namespace fs = std::filesystem;
  if (folder.empty())
    return "this model was read from no file: it has no folder to " + std::string(reading ? "read '" : "write '") + name +
           "' in";
  const fs::path relative(name);
  if (name.empty() || relative.is_absolute() ||
      std::any_of(relative.begin(), relative.end(), [](const fs::path& part) { return part == ".."; }))
    return "'" + name + "' is outside the model's folder: a model " + (reading ? "reads" : "writes") +
           " files beside itself only (docs/cpfg.md)";
  if (files.size() >= kMaxFiles) return "more than " + std::to_string(kMaxFiles) + " files opened";
  File f{(fs::path(folder) / relative).string(), "", true, reading, 0};
  if (reading) {
    const uint64_t left = kMaxInputBytes - std::min(bytes_read, kMaxInputBytes);
    Expected<std::string> text = read_text_file(f.path, static_cast<size_t>(left));
    if (!text.ok()) return failed_on(f.path, text.error());
    f.text = std::move(*text);
    bytes_read += f.text.size();
  }
  files.push_back(std::move(f));
  *id = static_cast<double>(files.size());
  return "";
}

namespace {
// The file of id `id`, or null when no open file has it.
ModelFiles::File* file_of(std::vector<ModelFiles::File>& files, double id) {
  if (!(id >= 1) || id != std::floor(id) || id > static_cast<double>(files.size())) return nullptr;
  ModelFiles::File& f = files[static_cast<size_t>(id) - 1];
  return f.open ? &f : nullptr;
}
const char* const kNoOpenFile = " is no open file (an id fopen returned, before its fclose)";
}  // namespace

std::string ModelFiles::scan(double id, std::string_view format, std::vector<double>& values, int* read) {
  File* f = file_of(files, id);
  if (!f) return index_text(id) + kNoOpenFile;
  if (!f->reading) return "the file " + index_text(id) + " was opened for writing (\"w\"): fscanf reads one opened with \"r\"";
  const std::string& t = f->text;
  size_t& pos = f->pos;
  int stored = 0, converted = 0;
  std::string error;
  auto skip_space = [&] {
    while (pos < t.size() && is_c_space(t[pos])) ++pos;
  };
  // C's result: the values stored, or EOF when the input ended before the first conversion.
  auto input_failure = [&] { *read = converted ? stored : -1; };
  *read = 0;
  for (size_t i = 0; i < format.size(); ++i) {
    const char ch = format[i];
    if (is_c_space(ch)) {
      skip_space();
      continue;
    }
    if (ch != '%') {
      if (pos >= t.size()) return input_failure(), "";
      if (t[pos] != ch) return *read = stored, "";  // a matching failure
      ++pos;
      continue;
    }
    const ScanConversion c = parse_scan_conversion(format, i, &error);
    if (!c.conversion) return error;  // check_scan_format refused it when it was compiled
    i = c.end - 1;
    skip_space();
    if (pos >= t.size()) return input_failure(), "";
    if (c.conversion == '%') {
      if (t[pos] != '%') return *read = stored, "";
      ++pos;
      continue;
    }
    // The number, as strtod reads one, at most `width` characters; C's '+' sign too.
    const size_t limit = c.width ? std::min(t.size(), pos + c.width) : t.size();
    size_t at = pos;
    if (at < limit && t[at] == '+') ++at;
    double v = 0;
    const auto [end, ec] = std::from_chars(t.data() + at, t.data() + limit, v);
    if (ec == std::errc::invalid_argument || (at > pos && at < limit && t[at] == '-')) return *read = stored, "";
    if (ec == std::errc::result_out_of_range || !std::isfinite(v))
      return "fscanf read a number that is not finite in '" + f->path + "' at byte " + std::to_string(pos);
    pos = static_cast<size_t>(end - t.data());
    ++converted;
    if (!c.suppressed) {
      if (static_cast<size_t>(stored) >= values.size()) return "fscanf's format reads more values than it was given targets";
      values[static_cast<size_t>(stored++)] = v;
    }
  }
  *read = stored;
  return "";
}

std::string ModelFiles::append(double id, const std::string& text) {
  File* f = file_of(files, id);
  if (!f) return index_text(id) + kNoOpenFile;
  if (f->reading) return "the file " + index_text(id) + " was opened for reading (\"r\"): fprintf writes one opened with \"w\"";
  if ((bytes += text.size()) > kMaxOutputBytes)
    return "the model wrote more than " + std::to_string(kMaxOutputBytes >> 20) + " MiB to its files";
  f->text += text;
  return "";
}

std::string ModelFiles::write(double id, bool close) {
  File* f = file_of(files, id);
  if (!f) return index_text(id) + kNoOpenFile;
  if (!f->reading)
    if (Status s = write_file_atomically(f->path, f->text); !s) return failed_on(f->path, s.error());
  if (close) {
    f->open = false;
    if (f->reading) std::string().swap(f->text);
  }
  return "";
}

std::string ModelFiles::close_all() {
  for (size_t k = 0; k < files.size(); ++k)
    if (files[k].open && !files[k].reading)
      if (std::string e = write(static_cast<double>(k + 1), true); !e.empty()) return e;
  return "";
}

}  // namespace sylva::lsys

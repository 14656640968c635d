// expr.h — the expression language of docs/spec/grammar.md, compiled once to bytecode.
//
// Expressions (arguments, conditions, probabilities, directive values) are parsed once
// and compiled into one flat instruction array per grammar; evaluation is a small stack
// machine over doubles. Constants are folded at compile time (defines are constants),
// and the two commonest shapes — a constant and a bare formal parameter — never touch
// the machine. Every arithmetic result is checked: a NaN or infinity, or a division by
// zero, raises EvalError with the source place of the operation.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"
#include "core/util/random.h"
#include "lsystem/spline_function.h"

namespace sylva::lsys {

enum class Op : uint8_t {
  kConst,       // push consts[arg]
  kSlot,        // push slots[arg]
  kAdd, kSub, kMul, kDiv, kPow, kNeg, kNot,
  kLt, kLe, kGt, kGe, kEq, kNe,
  kAndJump,     // pop a; if a == 0 { push 0; pc = arg } (short-circuit &&)
  kOrJump,      // pop a; if a != 0 { push 1; pc = arg } (short-circuit ||)
  kBool,        // replace top by (top != 0)
  kCall,        // call function `fn` (arity known per function)
  // Statements (cpfg files, docs/cpfg.md):
  kStore,       // slots[arg] = pop (a local variable)
  kGlobal,      // push globals[arg]
  kStoreGlobal, // globals[arg] = pop
  kJump,        // pc = arg
  kJumpIfZero,  // pop a; if a == 0 { pc = arg }
  kLoop,        // pc = arg (a loop's backward jump: counted against kMaxLoopIterations)
  kPop,         // drop the top (an expression used as a statement)
  // Arrays (cpfg's `define: { array a[n, m]; }`, CPFG manual 2.2.2), stored in the globals:
  kArrayIndex,  // pop the rank indices of array `arg` (first below); check each; push the element's global index
  kLoadAt,      // pop an index; push globals[index]
  kStoreAt,     // pop a value, pop an index; globals[index] = value
  kDup,         // push the top again
  kPrint,       // cpfg's printf: pop `pad` values, write formats[arg] with them (print_sink); push 0
  kRem,         // cpfg's %: pop b, pop a; push (int)a % (int)b, C's remainder
  kFileOpen,    // cpfg's fopen(formats[arg], "w"): push the new output file's id (EvalContext::files)
  kFilePrint,   // cpfg's fprintf: pop `pad` values and a file id, append formats[arg] with them; push 0
  kFileRead,    // cpfg's fopen(formats[arg], "r"): push the id of the file, read whole (EvalContext::files)
  // cpfg's fscanf: pop `pad` targets (Program::scans[arg]) and a file id, read the values into
  // the targets; push how many were read, or -1 at the file's end
  kFileScan,
};

enum class Func : uint8_t {
  kSin, kCos, kTan, kAsin, kAcos, kAtan, kAtan2, kSqrt, kExp, kLog, kPow, kAbs,
  kFloor, kCeil, kMin, kMax, kClamp, kRand, kUniform, kGauss,
  // The CPFG manual's chapter 5 (docs/cpfg.md): available in every grammar.
  kFabs, kTrunc, kSign, kRan, kNran, kBran, kBiran,
  kSrand,  // srand(s): restarts the random stream from s (EvalContext::reseed); returns 0
  kFunc,   // func(id, x): the grammar's user-defined function id at x (Program::functions)
  kStop,   // stop(n) (CPFG manual 5.6): the derivation ends after this step (EvalContext::stop); returns 0
  // curveX/Y/Z(id, t) and curveGAL(id) (CPFG manual 5.5): the view file's curve id (Program::curves)
  kCurveX, kCurveY, kCurveZ, kCurveGal,
  // fflush(id) and fclose(id) (CPFG manual 5.4): an output file written out (EvalContext::files)
  kFflush, kFclose
};

struct Instr {
  Op op;
  Func fn;        // for kCall
  uint16_t pad = 0;
  uint32_t arg;   // constant index, slot index or jump target
};

// A compiled expression: a constant, a slot read, or a range of the shared program.
struct Expr {
  enum class Kind : uint8_t { kNone, kConst, kSlot, kProgram };
  Kind kind = Kind::kNone;
  bool uses_random = false;
  uint32_t slot = 0;      // kSlot
  uint32_t begin = 0;     // kProgram: first instruction
  uint32_t end = 0;       // kProgram: one past the last
  double value = 0;       // kConst
  SourceLoc loc;          // where the expression starts
};

// Raised by evaluation: where the failing operation is written, and what went wrong.
struct EvalError {
  SourceLoc loc;
  std::string message;
};

// The most backward jumps one evaluation of a statement block may take: a loop that runs
// longer stops with an error at the loop (docs/cpfg.md, bounded time).
inline constexpr uint64_t kMaxLoopIterations = 10000000;

// What statements read and write besides their own slots: the L-system's global variables,
// and the seed a srand() asked for (the derivation's, when a Start/StartEach/EndEach block
// calls it).
// The files a cpfg model opens with fopen (CPFG manual 5.4; docs/cpfg.md "Files"): only in
// the model's folder. One opened with "w" is kept in memory and written whole and atomically
// (write_file_atomically, never onto an input) at its fflush, its fclose and, for one left
// open, at the derivation's end: at most kMaxOutputBytes in all. One opened with "r" is read
// whole when it opens (at most kMaxInputBytes in all) and fscanf reads on from where it left.
struct ModelFiles {
  static constexpr uint64_t kMaxOutputBytes = uint64_t{64} << 20;
  static constexpr uint64_t kMaxInputBytes = uint64_t{64} << 20;
  static constexpr size_t kMaxFiles = 256;
  std::string folder;  // the model's folder; empty: the model came from no file, fopen is an error
  struct File {
    std::string path;
    std::string text;  // written so far, or the whole file read
    bool open = true;
    bool reading = false;
    size_t pos = 0;    // reading: where the next fscanf starts
  };
  std::vector<File> files;  // by id − 1
  uint64_t bytes = 0, bytes_read = 0;
  // Each returns an error message, empty on success.
  std::string open(const std::string& name, bool reading, double* id);
  std::string append(double id, const std::string& text);
  std::string write(double id, bool close);
  // fscanf: the numbers `format` (check_scan_format said it reads `values.size()`) reads from the
  // file into `values`; *read is C's result: how many were read, or -1 when the file ended
  // before the first conversion.
  std::string scan(double id, std::string_view format, std::vector<double>& values, int* read);
  std::string close_all();  // writes every file still open for writing
};

struct EvalContext {
  double* globals = nullptr;
  bool reseeded = false;
  uint64_t reseed = 0;
  bool stop = false;  // a stop() was evaluated: the derivation ends after the current step
  ModelFiles* files = nullptr;  // a derivation's (fopen); null where statements open no files
};

// The evaluation stack's size in values: Program::run's fixed stack, and the depth the
// parser lets a compiled expression need ("expression nested too deeply" beyond).
inline constexpr int kMaxEvalStack = 512;

// A cpfg array: its elements are the globals base .. base + size − 1, row-major.
struct ArrayInfo {
  std::string name;
  uint32_t base = 0;
  std::vector<uint32_t> dims;  // each at least 1
};

// All compiled code of one grammar.
struct Program {
  std::vector<Instr> code;
  std::vector<double> consts;
  std::vector<SourceLoc> locs;  // parallel to code: the place of each operation
  std::vector<ArrayInfo> arrays;
  std::vector<SplineFunction> functions;  // func(id, x)'s, id − 1 (a vlab object's view file)
  std::vector<CpfgCurve> curves;          // curveX(id, t)'s and curveGAL(id)'s, id − 1 (its `curve:` lines)
  std::vector<std::string> formats;       // printf's format strings (checked when compiled)
  // An fscanf's: its format (formats[format]) and where each value goes, in order: a local
  // slot, or a global (an array's element is one), whose index the code pushes.
  struct Scan {
    uint32_t format = 0;
    std::vector<uint8_t> local;  // by target: 1 a slot, 0 a global
  };
  std::vector<Scan> scans;

  // Evaluates `e` with formal parameters `slots` and random stream `rng` (only touched
  // by rand/uniform/gauss). Throws EvalError on division by zero or a non-finite result.
  // Statements (kStore, kGlobal, kStoreGlobal, srand) write `slots` and `context`: they are
  // only compiled where the caller passes slots and a context with globals.
  double eval(const Expr& e, double* slots, Rng* rng, EvalContext* context = nullptr) const {
    switch (e.kind) {
      case Expr::Kind::kConst: return e.value;
      case Expr::Kind::kSlot: return slots[e.slot];
      default: return run(e, slots, rng, context);
    }
  }

 private:
  double run(const Expr& e, double* slots, Rng* rng, EvalContext* context) const;
};

// Where cpfg's printf statements write (CPFG manual 3.2; docs/cpfg.md): standard error by
// default (standard output carries `sylva derive`'s word). Tests replace it.
using PrintSink = void (*)(std::string_view text);
PrintSink set_print_sink(PrintSink sink);  // returns the one it replaces

// A printf format string's conversions (%d %i %u %o %x %X %c %e %E %f %F %g %G with flags,
// width and precision, and %%): how many values it takes, or an error message for one sylva
// cannot print (%s, %*d, an unknown conversion).
struct FormatCheck {
  int values = 0;
  std::string error;  // empty when the format is good
};
FormatCheck check_format(std::string_view format);
// An fscanf format's conversions (%f %e %g %E %G %F %a %A with width, `l` and `*`, and %%;
// white space and other characters match as in C's scanf): how many values it reads, or an
// error message for one sylva cannot read (every cpfg variable is a number: no %d, %s, %[).
FormatCheck check_scan_format(std::string_view format);
// The format with `values` put in (check_format said it takes that many).
std::string apply_format(std::string_view format, const double* values);

// Trigonometry in degrees, exact at multiples of 90° (sin_deg(180) == 0, not 1.2e-16),
// so ABOP's right-angle grammars give exact coordinates.
double sin_deg(double degrees);
double cos_deg(double degrees);

// Name, arity and whether it draws random numbers, for each Func.
struct FuncInfo {
  const char* name;
  int arity;
  bool random;
};
const FuncInfo& func_info(Func f);
// Looks a function up by name; false if there is none.
bool find_func(const std::string& name, Func* f);

}  // namespace sylva::lsys

#pragma once
// The VOF engine's linear solvers through PETSc: the process-wide start of PETSc, the momentum
// predictor's solver (BiCGStab + ILU over the cells it predicts) and the pressure solver over the active
// region (CG with GAMG, hypre BoomerAMG or ILU(0), its preconditioner kept across steps and refreshed
// every VofConfig::pressure_pc_refresh steps, saved into and restored from a checkpoint). The
// equations hand them coefficients; nothing else in the engine calls PETSc.
#include <petscksp.h>

#include <functional>

#include <string>
#include <vector>

#include "engine/vof/config.hpp"
#include "engine/vof/mpi/ranks.hpp"
#include "engine/vof/state.hpp"

namespace runout::engine::vof {

void petsc_check(PetscErrorCode e, const char* what);
/// PETSc (and with it MPI) is started once per process, on first use.
void petsc_init();

/// A sparse matrix in compressed rows: row r's entries are col/val[start[r] .. start[r + 1]),
/// columns ascending.
struct CsrMatrix {
  std::vector<PetscInt> start{0}, col;
  std::vector<double> val;
  int rows() const { return int(start.size()) - 1; }
};

/// The momentum predictor's system over the cells it predicts (the rows change with the material):
/// the velocity components share the matrix. Split over ranks: each rank's own rows, with the whole
/// system's column numbers, one PETSc matrix over the ranks (ILU: block Jacobi).
class MomentumSolver {
 public:
  MomentumSolver() = default;
  MomentumSolver(const MomentumSolver&) = delete;
  MomentumSolver& operator=(const MomentumSolver&) = delete;
  ~MomentumSolver();
  /// rtol: VofConfig::momentum_rtol; ranks: the run's.
  void setup(double rtol, const Ranks& ranks);
  /// The matrix for the next solves: this rank's rows of `total`, their columns the whole system's
  /// (made anew when its rows or structure changed; split over ranks, at every call).
  void set_matrix(const CsrMatrix& A, long long total);
  /// Solve with the right-hand side b and the initial guess x (a value per row); the solution into x.
  /// Returns the iterations; throws when the solver does not converge (t: the time, for the message).
  int solve(const std::vector<double>& b, std::vector<double>& x, double t);

 private:
  void destroy_system();
  const Ranks* ranks_ = nullptr;
  int n_ = -1;
  long long total_ = 0;  // the whole system's rows
  std::vector<PetscInt> start_, col_;  // the structure of M_
  Mat M_ = nullptr;
  ::Vec x_ = nullptr, b_ = nullptr;
  KSP ksp_ = nullptr;
};

/// The pressure system over the active region's cells (rows in the region's order; split over
/// ranks, each rank's own cells' rows, the ranks one after another, as one PETSc matrix over the
/// run's communicator).
class PressureSolver {
 public:
  PressureSolver(const VofConfig& cfg, const Ranks& ranks) : cfg_(cfg), ranks_(ranks) {}
  PressureSolver(const PressureSolver&) = delete;
  PressureSolver& operator=(const PressureSolver&) = delete;
  ~PressureSolver();

  /// The solver: CG with an algebraic multigrid preconditioner. Made anew with every system (GAMG
  /// keeps its coarse levels' solvers, whose sizes would not fit another); checks the
  /// preconditioner's name. Over several ranks "ilu" is block Jacobi with ILU(0) in each rank's
  /// block (PETSc's ILU is sequential).
  void make_ksp();
  /// (Re)create the system: this rank's `rows` rows from `first_row` of `total`, with own_nnz
  /// nonzeros per row in the rank's own columns and off_nnz in the other ranks'.
  void make_system(int rows, int first_row, long long total, const std::vector<int>& own_nnz, const std::vector<int>& off_nnz);
  /// The relative tolerance of the next solves: the last corrector's or the ones before it.
  void set_tolerance(bool final);

  /// Start the matrix (reuse: a later corrector of the step keeps the step's matrix).
  void begin_matrix(bool reuse);
  /// The off-diagonal entry (i, j) (whole-system rows and columns; i one of this rank's rows).
  void set_entry(PetscInt i, PetscInt j, double value);
  /// The diagonal (unless reuse), the right-hand side and the initial guess of every row; then the
  /// matrix assembled (unless reuse).
  void set_rows(const std::vector<double>& diag, const std::vector<double>& rhs, const std::vector<double>& x0, bool reuse);
  /// What solve() solves, by name at the call.
  struct Solve {
    bool initial = false;  ///< the initial hydrostatic solve: three passes
    bool reuse = false;    ///< the matrix of the solve before (a later corrector or non-orthogonal pass)
    bool closed = false;   ///< a closed domain: the correction fixed to zero in row 0, with diagonal diag0
    double diag0 = 0;
  };
  /// Solve at time t (for the error message). Returns the iterations.
  int solve(const Solve& s, double t);
  /// The solution, row by row.
  void solution(std::vector<double>& x) const;
  /// Add s to every row of the solution (a closed domain's level).
  void shift(double s);

  /// How a checkpoint names the system's columns. Empty: as the system's own (a run on one
  /// process: the active region's rows). A rank of a run over several stores the cells of its part
  /// (VofSolver gives the maps), which DistributedVof turns into the whole region's rows.
  struct PcColumns {
    std::function<int(PetscInt)> stored;  ///< the system's column as stored (-1: none)
    std::function<PetscInt(int)> system;  ///< a stored column as the system's (-1: none)
  };
  /// The pressure solver's cross-step state for a checkpoint: the refresh counter and the operators
  /// the preconditioner was built from (compressed rows over this rank's rows, in order; both share
  /// the active region's structure).
  void save_pc(VofState& st, const PcColumns& cols = {}) const;
  /// After make_system() for the restored region: the refresh counter, and the preconditioner
  /// built as the run that wrote the checkpoint built it (closed: placed where a closed domain's
  /// run had it).
  void restore_pc(const VofState& st, bool closed, const PcColumns& cols = {});

  bool later_outer = false;  ///< in an outer corrector after the step's first (the preconditioner is kept)
  double ksp_seconds = 0;    ///< time in KSPSolve since step() last took it

 private:
  void remember_pc(Mat Ap);
  void set_operator(Mat M, const VofState& st, const std::vector<double>& values, const PcColumns& cols);
  void timed_solve(Mat Ap);

  const VofConfig& cfg_;
  const Ranks& ranks_;
  int n_ = 0;
  int first_row_ = 0;
  Mat A_ = nullptr;
  ::Vec x_ = nullptr, b_ = nullptr, r_ = nullptr, dx_ = nullptr;
  KSP ksp_ = nullptr;
  Mat Apin_ = nullptr;  // closed domains: the matrix with row 0 pinned
  // Copies of the operators the preconditioner was built from, at the current solver's latest
  // build and at its first (nullptr: none built yet), and the number of builds. A checkpoint
  // carries them, so that restore_pc() builds the preconditioner the uninterrupted run keeps using
  // until its next refresh.
  Mat Apc_ = nullptr, Apc_first_ = nullptr;
  int pc_builds_ = 0;
  int steps_since_pc_ = 0;
  bool system_fresh_ = true;  // the system was just (re)created
};

}  // namespace runout::engine::vof

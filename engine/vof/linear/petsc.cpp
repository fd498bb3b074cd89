#include "engine/vof/linear/petsc.hpp"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <mutex>

namespace runout::engine::vof {

void petsc_check(PetscErrorCode e, const char* what) {
  if (e) throw VofError(std::string("PETSc: ") + what + " failed (error " + std::to_string(int(e)) + ")");
}

// Signals stay the program's business (a worker's or a CLI run's SIGTERM/SIGINT handler stops the
// run at the end of a step with a checkpoint; a server ignores SIGPIPE): PETSc's own handlers are
// removed, and since removing them leaves the default dispositions, the ones the program had set
// are put back.
void petsc_init() {
  static std::once_flag once;
  std::call_once(once, [] {
    PetscBool started = PETSC_FALSE;
    PetscInitialized(&started);
    if (!started) {
      std::vector<struct sigaction> before(NSIG);
      for (int sig = 1; sig < NSIG; ++sig) sigaction(sig, nullptr, &before[sig]);
      petsc_check(PetscInitializeNoArguments(), "PetscInitialize");
      PetscPopSignalHandler();
      for (int sig = 1; sig < NSIG; ++sig) {
        if (sig == SIGKILL || sig == SIGSTOP || sig == SIGCHLD) continue;
        struct sigaction now{};
        if (sigaction(sig, nullptr, &now) != 0) continue;
        if (now.sa_handler != before[sig].sa_handler) sigaction(sig, &before[sig], nullptr);
      }
    }
  });
}

// ---- the momentum predictor's solver ----

MomentumSolver::~MomentumSolver() {
  if (ksp_) KSPDestroy(&ksp_);
  if (M_) MatDestroy(&M_);
  if (x_) VecDestroy(&x_);
  if (b_) VecDestroy(&b_);
}

void MomentumSolver::setup(int cells, const std::vector<int>& nnz, double rtol) {
  n_ = cells;
  const std::vector<PetscInt> nz(nnz.begin(), nnz.end());
  petsc_check(MatCreateSeqAIJ(PETSC_COMM_SELF, n_, n_, 0, nz.data(), &M_), "MatCreateSeqAIJ");
  petsc_check(VecCreateSeq(PETSC_COMM_SELF, n_, &x_), "VecCreateSeq");
  petsc_check(VecDuplicate(x_, &b_), "VecDuplicate");
  petsc_check(KSPCreate(PETSC_COMM_SELF, &ksp_), "KSPCreate");
  petsc_check(KSPSetType(ksp_, KSPBCGS), "KSPSetType");
  PC pc;
  petsc_check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  petsc_check(PCSetType(pc, PCILU), "PCSetType ilu");
  petsc_check(KSPSetTolerances(ksp_, rtol, 1e-300, PETSC_DEFAULT, 2000), "KSPSetTolerances");
  petsc_check(KSPSetInitialGuessNonzero(ksp_, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  // PETSc options with the prefix runout_u_ override these.
  petsc_check(KSPSetOptionsPrefix(ksp_, "runout_u_"), "KSPSetOptionsPrefix");
  petsc_check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
}

void MomentumSolver::begin() { petsc_check(MatZeroEntries(M_), "MatZeroEntries"); }

void MomentumSolver::set(PetscInt row, PetscInt col, double value) {
  const PetscScalar v = value;
  petsc_check(MatSetValues(M_, 1, &row, 1, &col, &v, INSERT_VALUES), "MatSetValues");
}

void MomentumSolver::assemble() {
  petsc_check(MatAssemblyBegin(M_, MAT_FINAL_ASSEMBLY), "MatAssembly");
  petsc_check(MatAssemblyEnd(M_, MAT_FINAL_ASSEMBLY), "MatAssembly");
  petsc_check(KSPSetOperators(ksp_, M_, M_), "KSPSetOperators");
}

int MomentumSolver::solve(const std::vector<double>& b, std::vector<double>& x, double t) {
  for (PetscInt c = 0; c < n_; ++c) {
    VecSetValue(b_, c, b[c], INSERT_VALUES);
    VecSetValue(x_, c, x[c], INSERT_VALUES);
  }
  VecAssemblyBegin(b_);
  VecAssemblyEnd(b_);
  VecAssemblyBegin(x_);
  VecAssemblyEnd(x_);
  petsc_check(KSPSolve(ksp_, b_, x_), "KSPSolve (momentum)");
  KSPConvergedReason reason;
  KSPGetConvergedReason(ksp_, &reason);
  PetscInt k = 0;
  KSPGetIterationNumber(ksp_, &k);
  if (reason < 0)
    throw VofError("momentum solver (BiCGStab + ILU) did not converge at t = " + std::to_string(t) + " s: reason " +
                   std::to_string(int(reason)));
  const PetscScalar* xv;
  VecGetArrayRead(x_, &xv);
  std::copy(xv, xv + n_, x.begin());
  VecRestoreArrayRead(x_, &xv);
  return int(k);
}

}  // namespace runout::engine::vof

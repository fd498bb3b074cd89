#include "engine/vof/linear/petsc.hpp"

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <mutex>

#include "engine/vof/error.hpp"

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
  destroy_system();
  if (ksp_) KSPDestroy(&ksp_);
}

void MomentumSolver::destroy_system() {
  if (M_) MatDestroy(&M_);
  if (x_) VecDestroy(&x_);
  if (b_) VecDestroy(&b_);
}

void MomentumSolver::setup(double rtol, const Ranks& ranks) {
  ranks_ = &ranks;
  petsc_check(KSPCreate(ranks.comm().comm, &ksp_), "KSPCreate");
  petsc_check(KSPSetType(ksp_, KSPBCGS), "KSPSetType");
  PC pc;
  petsc_check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  petsc_check(PCSetType(pc, ranks.distributed() ? PCBJACOBI : PCILU), "PCSetType ilu");
  petsc_check(KSPSetTolerances(ksp_, rtol, 1e-300, PETSC_DEFAULT, 2000), "KSPSetTolerances");
  petsc_check(KSPSetInitialGuessNonzero(ksp_, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  // PETSc options with the prefix runout_u_ override these.
  petsc_check(KSPSetOptionsPrefix(ksp_, "runout_u_"), "KSPSetOptionsPrefix");
  petsc_check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
}

void MomentumSolver::set_matrix(const CsrMatrix& A, long long total) {
  const int n = A.rows();
  if (ranks_->distributed()) {  // the rows' columns differ with the ghosts' rows: made anew
    petsc_check(KSPReset(ksp_), "KSPReset");
    destroy_system();
    n_ = n;
    total_ = total;
    if (total_ == 0) return;
    const MPI_Comm comm = ranks_->comm().comm;
    const auto N = PetscInt(total);
    petsc_check(MatCreate(comm, &M_), "MatCreate");
    petsc_check(MatSetSizes(M_, n_, n_, N, N), "MatSetSizes");
    petsc_check(MatSetType(M_, MATMPIAIJ), "MatSetType");
    petsc_check(MatMPIAIJSetPreallocationCSR(M_, A.start.data(), A.col.data(), A.val.data()), "MatMPIAIJSetPreallocationCSR");
    petsc_check(VecCreateMPI(comm, n_, N, &x_), "VecCreateMPI");
    petsc_check(VecDuplicate(x_, &b_), "VecDuplicate");
    petsc_check(KSPSetOperators(ksp_, M_, M_), "KSPSetOperators");
    return;
  }
  if (n != n_ || A.start != start_ || A.col != col_) {
    petsc_check(KSPReset(ksp_), "KSPReset");  // (a new size: the old operators and factors go)
    destroy_system();
    n_ = n;
    start_ = A.start;
    col_ = A.col;
    if (n_ == 0) return;
    petsc_check(MatCreate(PETSC_COMM_SELF, &M_), "MatCreate");
    petsc_check(MatSetSizes(M_, n_, n_, n_, n_), "MatSetSizes");
    petsc_check(MatSetType(M_, MATSEQAIJ), "MatSetType");
    petsc_check(MatSeqAIJSetPreallocationCSR(M_, start_.data(), col_.data(), A.val.data()), "MatSeqAIJSetPreallocationCSR");
    petsc_check(VecCreateSeq(PETSC_COMM_SELF, n_, &x_), "VecCreateSeq");
    petsc_check(VecDuplicate(x_, &b_), "VecDuplicate");
  } else {
    if (n_ == 0) return;
    PetscScalar* v = nullptr;
    petsc_check(MatSeqAIJGetArray(M_, &v), "MatSeqAIJGetArray");
    std::copy(A.val.begin(), A.val.end(), v);
    petsc_check(MatSeqAIJRestoreArray(M_, &v), "MatSeqAIJRestoreArray");  // (marks the matrix changed)
  }
  petsc_check(KSPSetOperators(ksp_, M_, M_), "KSPSetOperators");
}

int MomentumSolver::solve(const std::vector<double>& b, std::vector<double>& x, double t) {
  if (ranks_->distributed() ? total_ == 0 : n_ <= 0) return 0;  // (split over ranks, a rank without rows still takes part)
  PetscScalar* v = nullptr;
  petsc_check(VecGetArray(b_, &v), "VecGetArray");
  std::copy(b.begin(), b.begin() + n_, v);
  VecRestoreArray(b_, &v);
  petsc_check(VecGetArray(x_, &v), "VecGetArray");
  std::copy(x.begin(), x.begin() + n_, v);
  VecRestoreArray(x_, &v);
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

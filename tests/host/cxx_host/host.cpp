// A C++ host calling wellposed's UMAT through the Fortran symbol umat_
// (gfortran's mangling), as a C or C++ FE code would. All arguments are
// passed by reference; CMNAME's length follows the 37 arguments as a
// hidden size_t (gfortran's convention for character dummies). Arrays
// are column-major (DDSDDE(i, j) is ddsdde[(j - 1) * NTENS + (i - 1)]).
//
// One elastic increment: K = 4e9, G = 1.5e9, beta = 0.315, beta_p = 0,
// k0 = 5.066e6, DSTRAN = (1e-6, 0, 0, 0, 0, 0) from a zero stress.
// Expected: STRESS(1) = (K + 4G/3)*1e-6 = 6000,
//           STRESS(2) = STRESS(3) = (K - 2G/3)*1e-6 = 3000.
#include <cstddef>
#include <cstdio>
#include <cstring>

extern "C" void umat_(double *stress, double *statev, double *ddsdde, double *sse,
                      double *spd, double *scd, double *rpl, double *ddsddt,
                      double *drplde, double *drpldt, const double *stran,
                      const double *dstran, const double *time, const double *dtime,
                      const double *temp, const double *dtemp, const double *predef,
                      const double *dpred, const char *cmname, const int *ndi,
                      const int *nshr, const int *ntens, const int *nstatv,
                      const double *props, const int *nprops, const double *coords,
                      const double *drot, double *pnewdt, const double *celent,
                      const double *dfgrd0, const double *dfgrd1, const int *noel,
                      const int *npt, const int *layer, const int *kspt,
                      const int *kstep, const int *kinc, std::size_t cmname_len);

int main() {
  const int ndi = 3, nshr = 3, ntens = 6, nstatv = 12, nprops = 5;
  const int noel = 1, npt = 1, layer = 1, kspt = 1, kstep = 1, kinc = 1;
  double stress[6] = {0}, statev[12] = {0}, ddsdde[36] = {0};
  double ddsddt[6] = {0}, drplde[6] = {0}, stran[6] = {0}, dstran[6] = {1.0e-6, 0, 0, 0, 0, 0};
  double sse = 0, spd = 0, scd = 0, rpl = 0, drpldt = 0;
  const double time[2] = {0, 0}, dtime = 1.0, temp = 0, dtemp = 0, celent = 1.0;
  const double predef[1] = {0}, dpred[1] = {0}, coords[3] = {0, 0, 0};
  const double eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double props[5] = {4.0e9, 1.5e9, 0.315, 0.0, 5.066e6};
  double pnewdt = 1.0;
  char cmname[80];
  std::memset(cmname, ' ', sizeof cmname);
  std::memcpy(cmname, "WELLPOSED", 9);

  umat_(stress, statev, ddsdde, &sse, &spd, &scd, &rpl, ddsddt, drplde, &drpldt, stran,
        dstran, time, &dtime, &temp, &dtemp, predef, dpred, cmname, &ndi, &nshr, &ntens,
        &nstatv, props, &nprops, coords, eye, &pnewdt, &celent, eye, eye, &noel, &npt,
        &layer, &kspt, &kstep, &kinc, sizeof cmname);

  for (int i = 0; i < ntens; ++i) std::printf("STRESS(%d) = %16.4f\n", i + 1, stress[i]);
  std::printf("DDSDDE(1,1) = %14.6E\n", ddsdde[0]);
  std::printf("DDSDDE(1,2) = %14.6E\n", ddsdde[ntens]);
  std::printf("STATUS = %8.3f\n", statev[11]);
  std::printf("PNEWDT = %8.3f\n", pnewdt);
  return 0;
}

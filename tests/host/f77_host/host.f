C     A Fortran 77 host, fixed form, calling the UMAT as a legacy FE code
C     would (no module, no interface, the Abaqus argument list), linked
C     with only -lwellposed -llapack -lblas: gfortran's umat_ reaches ours.
C     One elastic increment DSTRAN(1) = 1e-6 from zero stress with K = 4e9,
C     G = 1.5e9, beta = 0.315, beta_p = 0, k0 = 5.066e6 (NPROPS = 5).
C     Expected: STRESS(1) = (K + 4G/3)*1e-6 = 6000,
C               STRESS(2) = STRESS(3) = (K - 2G/3)*1e-6 = 3000.
      PROGRAM HOSTF
      IMPLICIT NONE
      INTEGER NTENS, NSTATV, NPROPS
      PARAMETER (NTENS = 6, NSTATV = 12, NPROPS = 5)
      DOUBLE PRECISION STRESS(NTENS), STATEV(NSTATV),
     1     DDSDDE(NTENS,NTENS), DDSDDT(NTENS), DRPLDE(NTENS),
     2     STRAN(NTENS), DSTRAN(NTENS), TIME(2), PREDEF(1),
     3     DPRED(1), PROPS(NPROPS), COORDS(3), DROT(3,3),
     4     DFGRD0(3,3), DFGRD1(3,3)
      DOUBLE PRECISION SSE, SPD, SCD, RPL, DRPLDT, DTIME, TEMP,
     1     DTEMP, PNEWDT, CELENT
      CHARACTER*80 CMNAME
      INTEGER NDI, NSHR, NOEL, NPT, LAYER, KSPT, KSTEP, KINC, I, J
      EXTERNAL UMAT
C
      DO 10 I = 1, NTENS
         STRESS(I) = 0.0D0
         DDSDDT(I) = 0.0D0
         DRPLDE(I) = 0.0D0
         STRAN(I) = 0.0D0
         DSTRAN(I) = 0.0D0
         DO 5 J = 1, NTENS
            DDSDDE(I,J) = 0.0D0
    5    CONTINUE
   10 CONTINUE
      DO 20 I = 1, NSTATV
         STATEV(I) = 0.0D0
   20 CONTINUE
      DO 30 I = 1, 3
         COORDS(I) = 0.0D0
         DO 25 J = 1, 3
            DROT(I,J) = 0.0D0
            DFGRD0(I,J) = 0.0D0
            DFGRD1(I,J) = 0.0D0
   25    CONTINUE
         DROT(I,I) = 1.0D0
         DFGRD0(I,I) = 1.0D0
         DFGRD1(I,I) = 1.0D0
   30 CONTINUE
      PROPS(1) = 4.0D9
      PROPS(2) = 1.5D9
      PROPS(3) = 0.315D0
      PROPS(4) = 0.0D0
      PROPS(5) = 5.066D6
      DSTRAN(1) = 1.0D-6
      TIME(1) = 0.0D0
      TIME(2) = 0.0D0
      DTIME = 1.0D0
      TEMP = 0.0D0
      DTEMP = 0.0D0
      PREDEF(1) = 0.0D0
      DPRED(1) = 0.0D0
      SSE = 0.0D0
      SPD = 0.0D0
      SCD = 0.0D0
      RPL = 0.0D0
      DRPLDT = 0.0D0
      PNEWDT = 1.0D0
      CELENT = 1.0D0
      CMNAME = 'WELLPOSED'
      NDI = 3
      NSHR = 3
      NOEL = 1
      NPT = 1
      LAYER = 1
      KSPT = 1
      KSTEP = 1
      KINC = 1
C
      CALL UMAT(STRESS, STATEV, DDSDDE, SSE, SPD, SCD, RPL, DDSDDT,
     1     DRPLDE, DRPLDT, STRAN, DSTRAN, TIME, DTIME, TEMP, DTEMP,
     2     PREDEF, DPRED, CMNAME, NDI, NSHR, NTENS, NSTATV, PROPS,
     3     NPROPS, COORDS, DROT, PNEWDT, CELENT, DFGRD0, DFGRD1,
     4     NOEL, NPT, LAYER, KSPT, KSTEP, KINC)
C
      DO 40 I = 1, NTENS
         WRITE (*, '(A,I1,A,F16.4)') 'STRESS(', I, ') = ', STRESS(I)
   40 CONTINUE
      WRITE (*, '(A,ES14.6)') 'DDSDDE(1,1) = ', DDSDDE(1,1)
      WRITE (*, '(A,ES14.6)') 'DDSDDE(1,2) = ', DDSDDE(1,2)
      WRITE (*, '(A,F8.3)') 'STATUS = ', STATEV(12)
      WRITE (*, '(A,F8.3)') 'PNEWDT = ', PNEWDT
      END

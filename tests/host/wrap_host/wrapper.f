C     A host's own UMAT that dispatches on the material name, as a code
C     with several user materials (or a UMAT that adds XIT on our status
C     -1) does: it is UMAT itself and calls ours under another name,
C     WELLPOSED_UMAT, made by renaming our symbol in a copy of the
C     installed libwellposed_nolto.a:
C       objcopy --redefine-sym umat_=wellposed_umat_ libwellposed_nolto.a
C     Materials not named WELLPOSED* get no answer (PNEWDT = -1).
      SUBROUTINE UMAT(STRESS, STATEV, DDSDDE, SSE, SPD, SCD, RPL,
     1     DDSDDT, DRPLDE, DRPLDT, STRAN, DSTRAN, TIME, DTIME, TEMP,
     2     DTEMP, PREDEF, DPRED, CMNAME, NDI, NSHR, NTENS, NSTATV,
     3     PROPS, NPROPS, COORDS, DROT, PNEWDT, CELENT, DFGRD0,
     4     DFGRD1, NOEL, NPT, LAYER, KSPT, KSTEP, KINC)
      IMPLICIT NONE
      CHARACTER*80 CMNAME
      INTEGER NDI, NSHR, NTENS, NSTATV, NPROPS, NOEL, NPT, LAYER,
     1     KSPT, KSTEP, KINC
      DOUBLE PRECISION STRESS(NTENS), STATEV(NSTATV),
     1     DDSDDE(NTENS,NTENS), DDSDDT(NTENS), DRPLDE(NTENS),
     2     STRAN(NTENS), DSTRAN(NTENS), TIME(2), PREDEF(1), DPRED(1),
     3     PROPS(NPROPS), COORDS(3), DROT(3,3), DFGRD0(3,3),
     4     DFGRD1(3,3), SSE, SPD, SCD, RPL, DRPLDT, DTIME, TEMP,
     5     DTEMP, PNEWDT, CELENT
      EXTERNAL WELLPOSED_UMAT
      IF (CMNAME(1:9) .NE. 'WELLPOSED') THEN
         PNEWDT = -1.0D0
         RETURN
      END IF
      CALL WELLPOSED_UMAT(STRESS, STATEV, DDSDDE, SSE, SPD, SCD, RPL,
     1     DDSDDT, DRPLDE, DRPLDT, STRAN, DSTRAN, TIME, DTIME, TEMP,
     2     DTEMP, PREDEF, DPRED, CMNAME, NDI, NSHR, NTENS, NSTATV,
     3     PROPS, NPROPS, COORDS, DROT, PNEWDT, CELENT, DFGRD0,
     4     DFGRD1, NOEL, NPT, LAYER, KSPT, KSTEP, KINC)
      END

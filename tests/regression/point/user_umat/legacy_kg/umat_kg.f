C     A legacy fixed-form Abaqus UMAT in three files for the test suite:
C     linear isotropic elasticity from PROPS(1) = K (bulk modulus) and
C     PROPS(2) = G (shear modulus), implicit typing through ABA_PARAM.INC.
C     The stiffness comes from KGSTIF (kg_stiffness.f), the check of the
C     moduli from KGCHK (kg_check.f90, free form, default REAL: built with
C     -fdefault-real-8). Bad moduli: a message through STDB_ABQERR, then
C     XIT. STATEV(1) = the Mises stress of the end state through SINV.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      INCLUDE 'ABA_PARAM.INC'
      CHARACTER*80 CMNAME
      CHARACTER*8 CHARV(1)
      LOGICAL OK
      DIMENSION STRESS(NTENS),STATEV(NSTATV),
     1 DDSDDE(NTENS,NTENS),DDSDDT(NTENS),DRPLDE(NTENS),
     2 STRAN(NTENS),DSTRAN(NTENS),TIME(2),PREDEF(1),DPRED(1),
     3 PROPS(NPROPS),COORDS(3),DROT(3,3),DFGRD0(3,3),DFGRD1(3,3)
      DIMENSION INTV(1),REALV(2)
      BULK = PROPS(1)
      SHEAR = PROPS(2)
      CALL KGCHK(BULK, SHEAR, OK)
      IF (.NOT. OK) THEN
        INTV(1) = NOEL
        REALV(1) = BULK
        REALV(2) = SHEAR
        CHARV(1) = 'UMAT_KG'
        CALL STDB_ABQERR(-1, '%S: K = %R and G = %R must both be '//
     1   '> 0 (element %I)', INTV, REALV, CHARV)
        CALL XIT
      END IF
      CALL KGSTIF(BULK, SHEAR, DDSDDE, NTENS, NDI)
      DO 20 I=1,NTENS
        DO 10 J=1,NTENS
          STRESS(I)=STRESS(I)+DDSDDE(I,J)*DSTRAN(J)
   10   CONTINUE
   20 CONTINUE
      CALL SINV(STRESS, SINV1, SINV2, NDI, NSHR)
      STATEV(1) = SINV2
      RETURN
      END

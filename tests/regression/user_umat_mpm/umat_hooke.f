C     A legacy fixed-form Abaqus UMAT in two files for the MPM tests:
C     linear isotropic elasticity from PROPS(1) = K (bulk modulus, Pa)
C     and PROPS(2) = G (shear modulus, Pa), implicit typing through
C     ABA_PARAM.INC. The stiffness DDSDDE and the stress change come
C     from HKSTEP (hooke_step.f). Bad PROPS (fewer than 2, K or G not
C     > 0): a message on unit 6 and XIT. STATEV is left as it is.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      INCLUDE 'ABA_PARAM.INC'
      CHARACTER*80 CMNAME
      DIMENSION STRESS(NTENS),STATEV(NSTATV),
     1 DDSDDE(NTENS,NTENS),DDSDDT(NTENS),DRPLDE(NTENS),
     2 STRAN(NTENS),DSTRAN(NTENS),TIME(2),PREDEF(1),DPRED(1),
     3 PROPS(NPROPS),COORDS(3),DROT(3,3),DFGRD0(3,3),DFGRD1(3,3)
      IF (NPROPS .LT. 2) THEN
        WRITE(6,100) NPROPS, NOEL
        CALL XIT
      END IF
      BULK = PROPS(1)
      SHEAR = PROPS(2)
      IF (.NOT. (BULK .GT. 0.D0 .AND. SHEAR .GT. 0.D0)) THEN
        WRITE(6,101) BULK, SHEAR, NOEL
        CALL XIT
      END IF
      CALL HKSTEP(BULK, SHEAR, STRESS, DSTRAN, DDSDDE, NDI, NSHR,
     1 NTENS)
      RETURN
  100 FORMAT(' UMAT_HOOKE: NPROPS = ',I3,' but PROPS(1) = K and ',
     1 'PROPS(2) = G are needed (element ',I8,')')
  101 FORMAT(' UMAT_HOOKE: K = ',1PE12.4,' and G = ',1PE12.4,
     1 ' Pa must both be > 0 (element ',I8,')')
      END

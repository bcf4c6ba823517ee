C     Helper of umat_hooke.f: isotropic elasticity on Abaqus components
C     (NDI direct, NSHR engineering shears). DDSDDE = K 1x1 + 2G (I - 1x1/3)
C     with G on the shear diagonal; the stress change is written as
C     2G dev(DSTRAN) + K tr(DSTRAN) on the direct components and G gamma on
C     the shears, the order of operations of wellposed's elastic step.
      SUBROUTINE HKSTEP(BULK, SHEAR, STRESS, DSTRAN, DDSDDE, NDI, NSHR,
     1 NTENS)
      INCLUDE 'ABA_PARAM.INC'
      DIMENSION STRESS(NTENS), DSTRAN(NTENS), DDSDDE(NTENS,NTENS)
      TWOG = 2.D0*SHEAR
      DO 20 J=1,NTENS
        DO 10 I=1,NTENS
          DDSDDE(I,J) = 0.D0
   10   CONTINUE
   20 CONTINUE
      DO 40 J=1,NDI
        DO 30 I=1,NDI
          DDSDDE(I,J) = BULK - TWOG/3.D0
   30   CONTINUE
        DDSDDE(J,J) = DDSDDE(J,J) + TWOG
   40 CONTINUE
      DO 50 I=NDI+1,NTENS
        DDSDDE(I,I) = SHEAR
   50 CONTINUE
      TRACE = 0.D0
      DO 60 I=1,NDI
        TRACE = TRACE + DSTRAN(I)
   60 CONTINUE
      DO 70 I=1,NDI
        STRESS(I) = STRESS(I) + (TWOG*(DSTRAN(I) - TRACE/3.D0)
     1   + BULK*TRACE)
   70 CONTINUE
      DO 80 I=NDI+1,NTENS
        STRESS(I) = STRESS(I) + SHEAR*DSTRAN(I)
   80 CONTINUE
      RETURN
      END

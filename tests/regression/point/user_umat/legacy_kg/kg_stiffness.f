C     The isotropic elastic stiffness of bulk modulus BULK and shear
C     modulus SHEAR in Abaqus order with engineering shears (the second
C     file of the legacy test UMAT, umat_kg.f).
      SUBROUTINE KGSTIF(BULK, SHEAR, DDSDDE, NTENS, NDI)
      INCLUDE 'ABA_PARAM.INC'
      DIMENSION DDSDDE(NTENS,NTENS)
      ALAMB = BULK - 2.D0*SHEAR/3.D0
      DO 20 I=1,NTENS
        DO 10 J=1,NTENS
          DDSDDE(I,J)=0.D0
   10   CONTINUE
   20 CONTINUE
      DO 40 I=1,NDI
        DO 30 J=1,NDI
          DDSDDE(I,J)=ALAMB
   30   CONTINUE
        DDSDDE(I,I)=ALAMB+2.D0*SHEAR
   40 CONTINUE
      DO 50 I=NDI+1,NTENS
        DDSDDE(I,I)=SHEAR
   50 CONTINUE
      RETURN
      END

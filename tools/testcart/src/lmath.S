/*
 * 32-bit multiply and divide for a plain 68000.
 *
 * GCC calls these for int/long arithmetic the 68000 has no instruction for.
 * Debian's m68k libgcc.a is built for the 68020 (it uses mulu.l / divu.l,
 * which raise illegal-instruction or address errors on a 68000), so the
 * cartridge carries its own.  Calling convention: arguments on the stack,
 * result in d0; d0-d1/a0-a1 are scratch, everything else is preserved.
 * The algorithms are the classic ones built from the 16-bit mulu/divu.
 */
    .text

/* long __mulsi3(long a, long b): low 32 bits of a*b (same for signed). */
    .globl __mulsi3
__mulsi3:
    move.w  4(%sp), %d0     /* a.hi */
    mulu.w  10(%sp), %d0    /* a.hi * b.lo */
    move.w  8(%sp), %d1     /* b.hi */
    mulu.w  6(%sp), %d1     /* b.hi * a.lo */
    add.w   %d1, %d0        /* only the low 16 bits of the cross terms matter */
    swap    %d0
    clr.w   %d0
    move.w  6(%sp), %d1     /* a.lo */
    mulu.w  10(%sp), %d1    /* a.lo * b.lo, full 32 bits */
    add.l   %d1, %d0
    rts

/* unsigned long __udivsi3(unsigned long n, unsigned long d) */
    .globl __udivsi3
__udivsi3:
    move.l  %d2, -(%sp)
    move.l  12(%sp), %d1    /* d1 = divisor */
    move.l  8(%sp), %d0     /* d0 = dividend */
    cmp.l   #0x10000, %d1
    bcc.s   .Lbig           /* divisor >= 2^16: estimate, then correct */
    /* 16-bit divisor: two divu steps, high word then low word. */
    move.l  %d0, %d2
    clr.w   %d2
    swap    %d2             /* d2 = dividend.hi */
    divu.w  %d1, %d2        /* d2 = rem:quot of the high word */
    move.w  %d2, %d0        /* save the high quotient */
    swap    %d0
    move.w  10(%sp), %d2    /* d2 = rem:dividend.lo */
    divu.w  %d1, %d2
    move.w  %d2, %d0        /* low quotient */
    bra.s   .Ldone
.Lbig:
    move.l  %d1, %d2        /* keep the divisor */
.Lshift:
    lsr.l   #1, %d1         /* shift both until the divisor fits 16 bits */
    lsr.l   #1, %d0
    cmp.l   #0x10000, %d1
    bcc.s   .Lshift
    divu.w  %d1, %d0        /* tentative quotient, at most one too large */
    and.l   #0xFFFF, %d0
    /* Multiply back: if quotient * divisor > dividend, subtract one. */
    move.l  %d2, %d1
    mulu.w  %d0, %d1        /* quotient * divisor.lo */
    swap    %d2
    mulu.w  %d0, %d2        /* quotient * divisor.hi */
    swap    %d2
    tst.w   %d2             /* product over 32 bits? */
    bne.s   .Lminus1
    add.l   %d2, %d1
    bcs.s   .Lminus1
    cmp.l   8(%sp), %d1
    bls.s   .Ldone
.Lminus1:
    subq.l  #1, %d0
.Ldone:
    move.l  (%sp)+, %d2
    rts

/* long __divsi3(long n, long d): quotient rounded toward zero. */
    .globl __divsi3
__divsi3:
    move.l  %d2, -(%sp)
    moveq   #1, %d2         /* d2 = sign of the result */
    move.l  12(%sp), %d1
    bpl.s   1f
    neg.l   %d1
    neg.b   %d2
1:  move.l  8(%sp), %d0
    bpl.s   2f
    neg.l   %d0
    neg.b   %d2
2:  move.l  %d1, -(%sp)
    move.l  %d0, -(%sp)
    bsr     __udivsi3
    addq.l  #8, %sp
    tst.b   %d2
    bpl.s   3f
    neg.l   %d0
3:  move.l  (%sp)+, %d2
    rts

/* long __modsi3(long n, long d) = n - (n / d) * d, sign of n. */
    .globl __modsi3
__modsi3:
    move.l  8(%sp), -(%sp)
    move.l  8(%sp), -(%sp)  /* (sp moved by 4) n */
    bsr     __divsi3
    addq.l  #8, %sp
    move.l  8(%sp), -(%sp)
    move.l  %d0, -(%sp)
    bsr     __mulsi3
    addq.l  #8, %sp
    move.l  4(%sp), %d1
    sub.l   %d0, %d1
    move.l  %d1, %d0
    rts

/* unsigned long __umodsi3(unsigned long n, unsigned long d) */
    .globl __umodsi3
__umodsi3:
    move.l  8(%sp), -(%sp)
    move.l  8(%sp), -(%sp)
    bsr     __udivsi3
    addq.l  #8, %sp
    move.l  8(%sp), -(%sp)
    move.l  %d0, -(%sp)
    bsr     __mulsi3
    addq.l  #8, %sp
    move.l  4(%sp), %d1
    sub.l   %d0, %d1
    move.l  %d1, %d0
    rts

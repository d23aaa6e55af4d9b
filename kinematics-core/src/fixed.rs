//! Fixed-point arithmetic for the solver: binary angles, sine/cosine, `atan2` and square root.
//!
//! Nothing here uses floating point. Ratios are Q30 (`1 << 30` = 1.0) held in `i64`, angles are
//! binary angles ([`Angle`], 2^32 per turn), so adding angles wraps around the circle for free.
//! Accuracy: sine and cosine within 2e-9, `atan2` within 2e-9 rad (1.3 binary-angle units; both
//! well below the 0.01 deg wire resolution, 1.7e-4 rad); the tests compare against `libm` over
//! the whole circle.

use core::num::NonZeroU64;

/// 1.0 in Q30.
pub const ONE: i64 = 1 << 30;

/// pi in Q30 (round(pi * 2^30)).
const PI_Q30: i64 = 3_373_259_426;
/// Binary angle of a quarter turn.
const QUARTER_TURN: i64 = 1 << 30;
/// atan(k / 64) for k = 0..=64 in binary-angle units (round(atan(k/64) * 2^32 / (2 pi))).
const ATAN_SIXTY_FOURTHS: [u32; 65] = [
    0,
    10_679_838,
    21_354_465,
    32_018_685,
    42_667_331,
    53_295_284,
    63_897_482,
    74_468_939,
    85_004_756,
    95_500_135,
    105_950_391,
    116_350_962,
    126_697_423,
    136_985_493,
    147_211_045,
    157_370_116,
    167_458_907,
    177_473_799,
    187_411_349,
    197_268_300,
    207_041_579,
    216_728_303,
    226_325_781,
    235_831_508,
    245_243_172,
    254_558_647,
    263_775_993,
    272_893_455,
    281_909_457,
    290_822_599,
    299_631_651,
    308_335_554,
    316_933_406,
    325_424_463,
    333_808_132,
    342_083_962,
    350_251_643,
    358_310_992,
    366_261_957,
    374_104_599,
    381_839_095,
    389_465_727,
    396_984_877,
    404_397_019,
    411_702_716,
    418_902_610,
    425_997_422,
    432_987_938,
    439_875_013,
    446_659_557,
    453_342_536,
    459_924_966,
    466_407_904,
    472_792_449,
    479_079_736,
    485_270_931,
    491_367_227,
    497_369_841,
    503_280_012,
    509_098_996,
    514_828_063,
    520_468_494,
    526_021_581,
    531_488_619,
    536_870_912,
];
/// Centidegrees in a full turn.
const CENTIDEG_PER_TURN: i64 = 36_000;

/// An angle as a binary fraction of a turn: 2^32 units per turn, wrapping (so +-360 deg is
/// free). Resolution 8.4e-8 deg.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Angle(pub i32);

impl Angle {
    /// Zero.
    pub const ZERO: Self = Self(0);
    /// A quarter turn (+90 deg).
    pub const QUARTER: Self = Self(1 << 30);
    /// Half a turn (180 deg).
    pub const HALF: Self = Self(i32::MIN);

    /// The angle of `centideg` hundredths of a degree (any value; wraps).
    pub const fn from_centideg(centideg: i32) -> Self {
        // 2^32 / 36000 = 2^27 / 1125: round to the nearest unit.
        let scaled = (centideg as i64) << 27;
        let half = if scaled >= 0 { 1125 / 2 } else { -(1125 / 2) };
        Self(((scaled + half) / 1125) as i32)
    }

    /// The angle in centidegrees, rounded to nearest, in -18000..=18000.
    pub const fn to_centideg(self) -> i32 {
        let scaled = self.0 as i64 * CENTIDEG_PER_TURN;
        ((scaled + (1 << 31)) >> 32) as i32
    }

    /// Sum, wrapping around the circle.
    #[must_use]
    pub const fn add(self, other: Self) -> Self {
        Self(self.0.wrapping_add(other.0))
    }

    /// Difference, wrapping around the circle.
    #[must_use]
    pub const fn sub(self, other: Self) -> Self {
        Self(self.0.wrapping_sub(other.0))
    }

    /// The opposite angle.
    #[must_use]
    pub const fn neg(self) -> Self {
        Self(self.0.wrapping_neg())
    }

    /// (sine, cosine) in Q30.
    pub fn sin_cos(self) -> (i64, i64) {
        // Nearest quarter turn q, remainder x in [-1/8, 1/8] turn.
        let quadrant = (self.0.wrapping_add(1 << 29) as u32) >> 30;
        let rest = self.0.wrapping_sub((quadrant << 30) as i32) as i64;
        // x radians in Q30 = rest * (2 pi / 2^32) * 2^30 = rest * pi / 2.
        let x = (rest * PI_Q30) >> 31;
        let (s, c) = (sin_small(x), cos_small(x));
        match quadrant {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        }
    }
}

/// Q30 product.
#[inline]
pub const fn mul(a: i64, b: i64) -> i64 {
    (a * b) >> 30
}

/// Taylor coefficients of sin: round((-1)^k / (2k+1)! * 2^30) for k = 1..=5.
const SIN_TAYLOR: [i64; 5] = [-178_956_971, 8_947_849, -213_044, 2_959, -27];
/// Taylor coefficients of cos: round((-1)^k / (2k)! * 2^30) for k = 1..=5.
const COS_TAYLOR: [i64; 5] = [-536_870_912, 44_739_243, -1_491_308, 26_631, -296];

/// 1 + c1 x2 + c2 x2^2 + ... (Horner), Q30.
#[inline]
fn even_series(x2: i64, coefficients: &[i64; 5]) -> i64 {
    let [c1, c2, c3, c4, c5] = *coefficients;
    let mut t = c5;
    t = c4 + mul(x2, t);
    t = c3 + mul(x2, t);
    t = c2 + mul(x2, t);
    t = c1 + mul(x2, t);
    ONE + mul(x2, t)
}

/// sin(x) for |x| <= pi/4 rad, x and result in Q30 (Taylor to x^11: truncation < 1e-11).
fn sin_small(x: i64) -> i64 {
    mul(x, even_series(mul(x, x), &SIN_TAYLOR))
}

/// cos(x) for |x| <= pi/4 rad, x and result in Q30 (Taylor to x^10: truncation < 2e-10).
fn cos_small(x: i64) -> i64 {
    even_series(mul(x, x), &COS_TAYLOR)
}

/// Bits to keep in the larger operand of [`atan2`] so that `min << 30` fits an `i64`.
const ATAN_INPUT_BITS: u32 = 32;

/// atan(u) = u - u^3/3 + u^5/5 in binary-angle units times 2^7: round(2^32 / (2 pi) * 2^7 / n)
/// for n = 1, 3, 5. For 0 <= u < 1/64 the terms dropped (from u^7/7) stay below 1e-14 rad, and u
/// (Q32) times the first fits a `u64`.
const ATAN_SERIES_BAM_Q7: [u64; 3] = [87_496_355_274, 29_165_451_758, 17_499_271_055];

/// The angle of the vector (x, y) (any common scale); 0 for the zero vector.
pub fn atan2(y: i64, x: i64) -> Angle {
    let (ax, ay) = (x.unsigned_abs(), y.unsigned_abs());
    let (big, small, swapped) = if ay > ax {
        (ay, ax, true)
    } else {
        (ax, ay, false)
    };
    let excess = (u64::BITS - big.leading_zeros()).saturating_sub(ATAN_INPUT_BITS);
    let Some(big_kept) = NonZeroU64::new(big >> excess) else {
        return Angle::ZERO;
    };
    let small = small >> excess;
    // The sixty-fourth c = k/64 at or below small / big, then atan(small / big) = atan(c) + atan(u)
    // with u = (small - c big) / (big + c small) in [0, 1/64), Q32 (small - c big < big < 2^32).
    let k = (small << 6) / big_kept;
    let big = big_kept.get();
    let u = (((small << 6) - k * big) << 32)
        .checked_div((big << 6) + k * small)
        .unwrap_or(0);
    let u2 = (u * u) >> 32;
    let [p1, p3, p5] = ATAN_SERIES_BAM_Q7;
    let series = p1 - ((u2 * (p3 - ((u2 * p5) >> 32))) >> 32);
    let base = ATAN_SIXTY_FOURTHS.get(k as usize).copied().unwrap_or(0);
    let mut a = i64::from(base) + ((u * series + (1 << 38)) >> 39) as i64;
    if swapped {
        a = QUARTER_TURN - a;
    }
    if x < 0 {
        a = 2 * QUARTER_TURN - a;
    }
    if y < 0 {
        a = -a;
    }
    Angle(a as i32)
}

/// num / den, 0 for a zero denominator (never reached: callers divide by positive values; this
/// keeps division panics out of the binary).
#[inline]
pub fn ratio(num: i64, den: i64) -> i64 {
    num.checked_div(den).unwrap_or(0)
}

/// `a / b` for `i128`, rounded towards zero like `/`; `None` for `b` = 0 and for `i128::MIN /
/// -1` (like `checked_div`).
///
/// Written out (shift and subtract, or one `u64` division when both fit) because on the ESP32
/// the compiler's own `i128` division is wrong: LLVM's Xtensa backend calls compiler_builtins'
/// `__divti3` / `__udivti3` with the two `i128` arguments where the Rust-compiled routine does
/// not look for them, so 1 000 000 007 / 7 gives 0 and some divisions never return
/// (docs/boards.md, "128-bit division on the ESP32"). `.ci/link-esp32` fails an image that
/// links either routine; use this instead of `/`, `%` or `checked_div` on `i128` or `u128`.
pub fn checked_div_i128(a: i128, b: i128) -> Option<i128> {
    if b == 0 || (a == i128::MIN && b == -1) {
        return None;
    }
    let q = div_u128(a.unsigned_abs(), b.unsigned_abs());
    // q <= 2^127; negated it fits (2^127 is i128::MIN), and a positive q is below 2^127 since
    // only i128::MIN / -1 would reach it.
    Some(if (a < 0) != (b < 0) {
        0u128.wrapping_sub(q) as i128
    } else {
        q as i128
    })
}

/// `n / d` for `d` > 0, without the compiler's 128-bit division (see [`checked_div_i128`]).
fn div_u128(n: u128, d: u128) -> u128 {
    if d == 0 || d > n {
        return 0;
    }
    if let (Ok(n), Ok(d)) = (u64::try_from(n), u64::try_from(d)) {
        return u128::from(n.checked_div(d).unwrap_or(0));
    }
    // Long division, one quotient bit per step from the highest that can be set.
    let shift = d.leading_zeros() - n.leading_zeros();
    let (mut d, mut rest, mut q) = (d << shift, n, 0u128);
    for _ in 0..=shift {
        q <<= 1;
        if rest >= d {
            rest -= d;
            q |= 1;
        }
        d >>= 1;
    }
    q
}

/// Square root of `n`, rounded down, digit by digit: shifts, compares and subtractions only
/// (`u128::isqrt` divides, with the compiler's 128-bit division: see [`checked_div_i128`]).
pub fn isqrt_u128(n: u128) -> u128 {
    if n == 0 {
        return 0;
    }
    // The highest power of 4 not above n.
    let mut bit = 1u128 << ((127 - n.leading_zeros()) & !1);
    let (mut rest, mut root) = (n, 0u128);
    while bit != 0 {
        if rest >= root + bit {
            rest -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    root
}

/// Right shift that leaves the top eight bits of a normalised [`sqrt`] argument (in
/// [2^61, 2^63)) as the index into [`SQRT_SEEDS`].
const SQRT_SEED_SHIFT: u32 = 55;

/// Starting values for [`sqrt`]: entry i is sqrt((i + 1/2) * 2^55), the root of the middle of
/// the arguments with top bits i, in units of 2^16. Within an interval the root differs from it
/// by under 2^-8 (relative). Entries below 64 are never used (normalised arguments are at least
/// 2^61) and kept so that any byte indexes the table.
const SQRT_SEEDS: [u16; 256] = sqrt_seeds();

/// Computes [`SQRT_SEEDS`] (at compile time).
#[allow(clippy::indexing_slicing)] // i < 256 = the array's length; evaluated by the compiler
const fn sqrt_seeds() -> [u16; 256] {
    let mut seeds = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let middle = (2 * i as u64 + 1) << (SQRT_SEED_SHIFT - 1);
        seeds[i] = (middle.isqrt() >> 16) as u16;
        i += 1;
    }
    seeds
}

/// Square root of a non-negative value, rounded down; 0 for negative input.
///
/// The argument is scaled by a power of 4 into m in [2^61, 2^63) (so sqrt(m) < 2^31.5 and r * r
/// below fits a `u64`), a table gives sqrt(m) to a relative error d <= 2^-8, and two Newton
/// steps r <- (r + m / r) / 2 follow. Rounded down, a Newton step never goes below floor(sqrt(m))
/// and leaves a relative excess of at most d^2 / (2 (1 - d)): 2^-17 after the first, then at
/// most 2^31.5 * 2^-34 / 2 < 0.1 absolute after the second, so r is floor(sqrt(m)) or one more.
/// One comparison settles which, and floor(sqrt(n)) = floor(sqrt(m)) >> k for m = n * 4^k.
pub fn sqrt(v: i64) -> i64 {
    if v <= 0 {
        return 0;
    }
    let n = v.unsigned_abs();
    // n < 2^63: at least one leading zero.
    let half_shift = n.leading_zeros().saturating_sub(1) / 2;
    let m = n << (2 * half_shift);
    let seed = SQRT_SEEDS
        .get(usize::from((m >> SQRT_SEED_SHIFT) as u8))
        .copied()
        .unwrap_or(0);
    let mut r = u64::from(seed) << 16;
    for _ in 0..2 {
        r = (r + m.checked_div(r).unwrap_or(0)) >> 1;
    }
    if r * r > m {
        r -= 1;
    }
    (r >> half_shift) as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn division_of_i128_written_out_matches_the_operator() {
        let cases: [(i128, i128); 12] = [
            (1_000_000_007, 7),
            (-412_703_666_745_104_000_000_000, 3),
            (-412_703_666_745_104_000_000_000, 5_000_000_000),
            (-412_703_666_745_104_000_000_000, 21_768_192_896_800_000_000),
            (i128::MAX, 340_282_366_920_938_463_463),
            (1_000_000_000_000_000_000_000, -18_446_744_073_709_551_617),
            (i128::MIN, 1),
            (i128::MIN, 2),
            (i128::MIN, i128::MIN),
            (i128::MAX, i128::MIN),
            (5, 7),
            (-7, 7),
        ];
        for (a, b) in cases {
            assert_eq!(checked_div_i128(a, b), a.checked_div(b), "{a} / {b}");
        }
        assert_eq!(checked_div_i128(1, 0), None);
        assert_eq!(checked_div_i128(i128::MIN, -1), None);
        for n in [
            0,
            1,
            2,
            3,
            4,
            15,
            16,
            17,
            u128::from(u64::MAX),
            u128::MAX,
            u128::MAX >> 1,
        ] {
            assert_eq!(isqrt_u128(n), n.isqrt(), "sqrt {n}");
        }
    }

    proptest::proptest! {
        // A failure is printed, never written to a file that would fail every later run.
        #![proptest_config(proptest::prelude::ProptestConfig {
            failure_persistence: None,
            ..proptest::prelude::ProptestConfig::default()
        })]

        /// Every magnitude of dividend and divisor, each a random value shifted right by a
        /// random amount.
        #[test]
        fn division_of_i128_written_out_matches_the_operator_everywhere(
            a in proptest::prelude::any::<i128>(),
            b in proptest::prelude::any::<i128>(),
            a_shift in 0u32..128,
            b_shift in 0u32..128,
        ) {
            let (a, b) = (a >> a_shift, b >> b_shift);
            proptest::prop_assert_eq!(checked_div_i128(a, b), a.checked_div(b));
        }

        /// Every magnitude.
        #[test]
        fn square_root_of_u128_written_out_matches_isqrt(
            n in proptest::prelude::any::<u128>(),
            shift in 0u32..128,
        ) {
            let n = n >> shift;
            proptest::prop_assert_eq!(isqrt_u128(n), n.isqrt());
        }
    }

    fn to_rad(a: Angle) -> f64 {
        a.0 as f64 * core::f64::consts::TAU / 4_294_967_296.0
    }

    #[test]
    fn sin_cos_match_libm_around_the_circle() {
        let mut worst = 0.0f64;
        for i in 0..100_000i64 {
            let a = Angle((i * 42_949 - (1 << 31)) as i32);
            let (s, c) = a.sin_cos();
            let r = to_rad(a);
            worst = worst.max((s as f64 / ONE as f64 - libm::sin(r)).abs());
            worst = worst.max((c as f64 / ONE as f64 - libm::cos(r)).abs());
        }
        assert!(worst < 3e-9, "worst trig error {worst}");
    }

    #[test]
    fn atan2_matches_libm_in_every_octant_and_scale() {
        let mut worst = 0.0f64;
        for i in 0..20_000i64 {
            let r = i as f64 * core::f64::consts::TAU / 20_000.0 - core::f64::consts::PI;
            for scale in [3.0e3, 1.0e6, 7.0e11, 4.0e17] {
                let (y, x) = ((libm::sin(r) * scale) as i64, (libm::cos(r) * scale) as i64);
                let got = to_rad(atan2(y, x));
                let want = libm::atan2(y as f64, x as f64);
                let mut d = (got - want).abs();
                d = d.min((d - core::f64::consts::TAU).abs());
                worst = worst.max(d);
            }
        }
        assert!(worst < 1e-8, "worst atan2 error {worst} rad");
    }

    #[test]
    fn atan_table_matches_libm() {
        for (k, &entry) in ATAN_SIXTY_FOURTHS.iter().enumerate() {
            let want = libm::atan(k as f64 / 64.0) * 4_294_967_296.0 / core::f64::consts::TAU;
            assert_eq!(i64::from(entry), libm::round(want) as i64, "atan({k}/64)");
        }
    }

    #[test]
    fn atan2_of_axes_is_exact() {
        assert_eq!(atan2(0, 5), Angle(0));
        assert_eq!(atan2(5, 0), Angle(1 << 30));
        assert_eq!(atan2(0, -5).to_centideg().abs(), 18000);
        assert_eq!(atan2(-5, 0), Angle(-(1 << 30)));
        assert_eq!(atan2(0, 0), Angle(0));
        assert_eq!(atan2(7, 7).to_centideg(), 4500);
    }

    #[test]
    fn centidegrees_round_trip_and_wrap() {
        for cd in -18_000..=18_000 {
            let back = Angle::from_centideg(cd).to_centideg();
            assert!(
                back == cd || (cd.abs() == 18_000 && back.abs() == 18_000),
                "{cd} -> {back}"
            );
        }
        assert_eq!(Angle::from_centideg(36_000 + 1234).to_centideg(), 1234);
        assert_eq!(Angle::from_centideg(-27_000).to_centideg(), 9000);
    }

    #[test]
    fn sqrt_rounds_down_and_rejects_negative() {
        assert_eq!(sqrt(0), 0);
        assert_eq!(sqrt(-4), 0);
        assert_eq!(sqrt(99), 9);
        assert_eq!(sqrt(1 << 60), 1 << 30);
    }

    #[test]
    fn sqrt_matches_the_exact_root_at_every_scale() {
        let check = |v: i64| {
            assert_eq!(sqrt(v), v.unsigned_abs().isqrt() as i64, "sqrt({v})");
        };
        for v in 0..100_000 {
            check(v);
        }
        // Around squares (the rounding boundaries) and the table's interval ends, every scale.
        for bits in 0..32 {
            for step in 0..500i128 {
                let root = (1i128 << bits) + step * ((1i128 << bits) / 500).max(1);
                for v in [root * root - 1, root * root, root * root + 1] {
                    check(i64::try_from(v).unwrap_or(i64::MAX));
                }
            }
        }
        for shift in 0..=SQRT_SEED_SHIFT {
            for top in 1u64..256 {
                let edge = ((top << SQRT_SEED_SHIFT) >> shift) as i64;
                for v in [edge - 1, edge, edge + 1] {
                    check(v.max(0));
                }
            }
        }
        check(i64::MAX);
        // Pseudo-random values of every magnitude.
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check((x >> (x % 64)) as i64 & i64::MAX);
        }
    }
}

//! What the two x86 lane types share: `sse41`'s `F32x4` and `avx2`'s
//! `F32x8` are the same code over registers of two widths. Each file
//! invokes these macros with its register type, its width, its macro that
//! runs an intrinsic (whose `// SAFETY:` names the detected features) and
//! its intrinsics; a macro expands to exactly the code it stands for, so
//! no instruction changes. What differs stays in the files: comparisons
//! (AVX's predicate form), `mul_add` (SSE4.1 has none), the gather and
//! scatter (one AVX load per row, two SSE ones).

/// The mask's bit operations (and `Mask`), the float's arithmetic
/// operators, `Debug` for both, `to_array` and `sign_bit`.
macro_rules! x86_lane_types {
    (
        $float:ident, $mask:ident, $reg:ty, $width:literal, $run:ident,
        set1: $set1:ident, and: $and:ident, or: $or:ident, xor: $xor:ident,
        andnot: $andnot:ident, all_ones: $all_ones:expr, movemask: $movemask:ident,
        add: $add:ident, sub: $sub:ident, mul: $mul:ident, div: $div:ident $(,)?
    ) => {
        #[inline(always)]
        fn sign_bit() -> $reg {
            $run!($set1(-0.0))
        }

        impl $float {
            #[inline(always)]
            fn to_array(self) -> [f32; $width] {
                let mut out = [0.0; $width];
                self.store(&mut out);
                out
            }
        }

        impl fmt::Debug for $float {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                self.to_array().fmt(f)
            }
        }

        impl fmt::Debug for $mask {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let bits = $run!($movemask(self.0));
                f.debug_list()
                    .entries((0..$width).map(|i| bits >> i & 1 == 1))
                    .finish()
            }
        }

        impl BitAnd for $mask {
            type Output = Self;
            #[inline(always)]
            fn bitand(self, rhs: Self) -> Self {
                Self($run!($and(self.0, rhs.0)))
            }
        }

        impl BitOr for $mask {
            type Output = Self;
            #[inline(always)]
            fn bitor(self, rhs: Self) -> Self {
                Self($run!($or(self.0, rhs.0)))
            }
        }

        impl Not for $mask {
            type Output = Self;
            #[inline(always)]
            fn not(self) -> Self {
                Self($run!($xor(self.0, $all_ones)))
            }
        }

        impl Mask for $mask {
            #[inline(always)]
            fn and_not(self, other: Self) -> Self {
                Self($run!($andnot(other.0, self.0)))
            }
        }

        x86_binary_op!($float, $run, Add, add, AddAssign, add_assign, $add);
        x86_binary_op!($float, $run, Sub, sub, SubAssign, sub_assign, $sub);
        x86_binary_op!($float, $run, Mul, mul, MulAssign, mul_assign, $mul);

        impl Div for $float {
            type Output = Self;
            #[inline(always)]
            fn div(self, rhs: Self) -> Self {
                Self($run!($div(self.0, rhs.0)))
            }
        }

        impl Neg for $float {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Self($run!($xor(self.0, sign_bit())))
            }
        }
    };
}

/// One arithmetic operator and its assigning form.
macro_rules! x86_binary_op {
    (
        $float:ident, $run:ident,
        $trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident
    ) => {
        impl $trait for $float {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self($run!($intrinsic(self.0, rhs.0)))
            }
        }
        impl $assign_trait for $float {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

/// The `Lane` methods written the same way at both widths, inside the
/// `impl Lane` block.
macro_rules! x86_lane_methods {
    (
        $width:literal, $run:ident,
        set1: $set1:ident, loadu: $loadu:ident, storeu: $storeu:ident,
        sqrt: $sqrt:ident, andnot: $andnot:ident, and: $and:ident, or: $or:ident,
        round: $round:ident, min: $min:ident, max: $max:ident, blendv: $blendv:ident $(,)?
    ) => {
        const WIDTH: usize = $width;

        #[inline(always)]
        fn splat(value: f32) -> Self {
            Self($run!($set1(value)))
        }
        #[inline(always)]
        fn load(src: &[f32]) -> Self {
            let src: &[f32; $width] = src[..$width].try_into().expect("a lane's width");
            // SAFETY: `src` is `WIDTH` readable floats, `loadu` takes any
            // alignment, and the module's features were detected.
            Self(unsafe { $loadu(src.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, dst: &mut [f32]) {
            let dst: &mut [f32; $width] = (&mut dst[..$width]).try_into().expect("a lane's width");
            // SAFETY: `dst` is `WIDTH` writable floats, `storeu` takes any
            // alignment, and the module's features were detected.
            unsafe { $storeu(dst.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            Self($run!($sqrt(self.0)))
        }
        #[inline(always)]
        fn abs(self) -> Self {
            Self($run!($andnot(sign_bit(), self.0)))
        }
        #[inline(always)]
        fn round(self) -> Self {
            Self($run!($round::<
                { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
            >(self.0)))
        }
        #[inline(always)]
        fn min(self, other: Self) -> Self {
            Self($run!($min(self.0, other.0)))
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            Self($run!($max(self.0, other.0)))
        }
        #[inline(always)]
        fn copysign(self, sign: Self) -> Self {
            let s = sign_bit();
            Self($run!($or($andnot(s, self.0), $and(s, sign.0))))
        }
        #[inline(always)]
        fn select(mask: Self::Mask, on_true: Self, on_false: Self) -> Self {
            Self($run!($blendv(on_false.0, on_true.0, mask.0)))
        }
        #[inline(always)]
        fn reduce_add(self) -> f32 {
            let a = self.to_array();
            let mut sum = a[0];
            for x in &a[1..] {
                sum += x;
            }
            sum
        }
    };
}

//! Which instruction set the traversal of a [`super::WideBvh`] runs on:
//! the kernels, their names, what the CPU offers, and the choice between
//! them at run time (`auto` takes the widest the CPU runs).

use std::fmt;
use std::str::FromStr;

/// An implementation of the per-node and per-leaf kernels. Every kernel
/// visits the same nodes and gives the same answers, bit for bit; they
/// differ only in speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// One lane at a time; runs everywhere.
    Scalar,
    /// AVX2 kernels in a traversal compiled for AVX2, FMA, BMI1 and POPCNT
    /// (x86-64 CPUs with AVX2, which all have the other three).
    Avx2,
    /// AVX-512 kernels (F, VL, DQ: mask registers, compress, 32 vector
    /// registers) on 256-bit registers, in a traversal compiled for them
    /// as well as AVX2.
    Avx512,
    /// The AVX-512 kernels, with a closest-hit ray's leaf and the next
    /// leaf on its stack tested in one pass of the 512-bit (zmm)
    /// registers; chosen by `auto` only where that pays
    /// ([`Kernel::prefers_zmm`]).
    Avx512Zmm,
}

/// What `--kernel` asks for: a kernel, or the widest one the CPU runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum KernelChoice {
    #[default]
    Auto,
    Only(Kernel),
}

/// A kernel this CPU cannot run.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the {0} kernel needs {needs}, which this CPU does not have; choose auto, or one of: {supported}", needs = .0.needs(), supported = supported_names())]
pub struct UnsupportedKernel(pub Kernel);

/// A name `--kernel` does not know.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown kernel '{0}': expected auto, avx512-zmm, avx512, avx2 or scalar")]
pub struct UnknownKernel(pub String);

impl Kernel {
    /// Widest first.
    pub const ALL: [Kernel; 4] = [
        Kernel::Avx512Zmm,
        Kernel::Avx512,
        Kernel::Avx2,
        Kernel::Scalar,
    ];

    /// The fastest kernel this CPU runs: the widest it supports, except
    /// that the 512-bit pass is taken only where it was measured to pay.
    pub fn detect() -> Kernel {
        Kernel::ALL
            .into_iter()
            .filter(|&k| k != Kernel::Avx512Zmm || Kernel::prefers_zmm())
            .find(|k| k.is_supported())
            .unwrap_or(Kernel::Scalar)
    }

    /// Whether this CPU is one whose closest-hit rays run faster with two
    /// leaves in one 512-bit pass than with one leaf in 256-bit registers:
    /// AMD's from family 26 (Zen 5) on, whose vector units are 512 bits
    /// wide (measured on family 26 only; older AMD CPUs split 512-bit
    /// operations in two). On
    /// an Intel Xeon with AVX-512 the pass made primary rays 5-10% slower
    /// (Embree, too, keeps to 256-bit registers there); see
    /// docs/performance.md, "Kernels and instruction sets".
    pub fn prefers_zmm() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::__cpuid;
            let vendor = __cpuid(0);
            let amd = (vendor.ebx, vendor.edx, vendor.ecx)
                == (
                    u32::from_le_bytes(*b"Auth"),
                    u32::from_le_bytes(*b"enti"),
                    u32::from_le_bytes(*b"cAMD"),
                );
            let signature = __cpuid(1).eax;
            let family = ((signature >> 8) & 0xf) + ((signature >> 20) & 0xff);
            amd && family >= 26
        }
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// `choice` made concrete: the detected kernel for `Auto`, or the one
    /// asked for if this CPU runs it.
    pub fn resolve(choice: KernelChoice) -> Result<Kernel, UnsupportedKernel> {
        match choice {
            KernelChoice::Auto => Ok(Kernel::detect()),
            KernelChoice::Only(kernel) if kernel.is_supported() => Ok(kernel),
            KernelChoice::Only(kernel) => Err(UnsupportedKernel(kernel)),
        }
    }

    pub fn is_supported(self) -> bool {
        match self {
            Kernel::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
                    && std::arch::is_x86_feature_detected!("bmi1")
                    && std::arch::is_x86_feature_detected!("popcnt")
            }
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 | Kernel::Avx512Zmm => {
                Kernel::Avx2.is_supported()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                    && std::arch::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2 | Kernel::Avx512 | Kernel::Avx512Zmm => false,
        }
    }

    /// The name `--kernel` takes.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Scalar => "scalar",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
            Kernel::Avx512Zmm => "avx512-zmm",
        }
    }

    /// The CPU features the kernel runs on, for messages.
    fn needs(self) -> &'static str {
        match self {
            Kernel::Scalar => "nothing",
            Kernel::Avx2 => "x86-64 with AVX2, FMA, BMI1 and POPCNT",
            Kernel::Avx512 | Kernel::Avx512Zmm => "x86-64 with AVX-512 F, VL and DQ (and AVX2)",
        }
    }
}

/// The kernels this CPU runs, widest first, comma-separated.
fn supported_names() -> String {
    let names: Vec<&str> = Kernel::ALL
        .into_iter()
        .filter(|k| k.is_supported())
        .map(Kernel::name)
        .collect();
    names.join(", ")
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Kernel {
    type Err = UnknownKernel;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Kernel::ALL
            .into_iter()
            .find(|k| k.name() == text)
            .ok_or_else(|| UnknownKernel(text.to_string()))
    }
}

impl fmt::Display for KernelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KernelChoice::Auto => f.write_str("auto"),
            KernelChoice::Only(kernel) => kernel.fmt(f),
        }
    }
}

impl FromStr for KernelChoice {
    type Err = UnknownKernel;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        match text {
            "auto" => Ok(KernelChoice::Auto),
            _ => text.parse().map(KernelChoice::Only),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_named() {
        for text in ["auto", "avx512-zmm", "avx512", "avx2", "scalar"] {
            let choice: KernelChoice = text.parse().unwrap();
            assert_eq!(choice.to_string(), text);
        }
        assert_eq!(
            "sse".parse::<KernelChoice>(),
            Err(UnknownKernel("sse".into()))
        );
        assert_eq!(
            UnknownKernel("sse".into()).to_string(),
            "unknown kernel 'sse': expected auto, avx512-zmm, avx512, avx2 or scalar"
        );
    }

    /// `auto` is the widest supported kernel, the 512-bit pass only
    /// where the CPU prefers it; a kernel the CPU lacks is refused with
    /// what it needs, one it has is given back.
    #[test]
    fn choices_resolve_to_what_the_cpu_runs() {
        let detected = Kernel::resolve(KernelChoice::Auto).unwrap();
        assert!(detected.is_supported());
        let widest = Kernel::ALL.into_iter().find(|k| k.is_supported());
        let expected = match widest {
            Some(Kernel::Avx512Zmm) if !Kernel::prefers_zmm() => Some(Kernel::Avx512),
            widest => widest,
        };
        assert_eq!(Some(detected), expected);
        for kernel in Kernel::ALL {
            match Kernel::resolve(KernelChoice::Only(kernel)) {
                Ok(resolved) => {
                    assert!(kernel.is_supported());
                    assert_eq!(resolved, kernel);
                }
                Err(error) => {
                    assert!(!kernel.is_supported());
                    let message = error.to_string();
                    assert!(message.contains(kernel.needs()), "{message}");
                    assert!(message.contains("scalar"), "{message}");
                }
            }
        }
    }
}

//! Buffers of `real`s, `f32` or `f64` to match the program's precision.

use ocl::{Buffer, Kernel, MemFlags, Queue};

use super::device::opencl;
use crate::error::Result;
use crate::quality::Precision;

/// A buffer of `real`s in the program's precision.
#[derive(Debug)]
pub(crate) enum RealBuffer {
    F32(Buffer<f32>),
    F64(Buffer<f64>),
}

impl RealBuffer {
    pub(crate) fn new(queue: &Queue, precision: Precision, values: &[f64]) -> Result<Self> {
        Self::with_flags(queue, precision, values, MemFlags::new().read_only())
    }

    /// A buffer the kernel may write, of `len` zeros.
    pub(crate) fn output(queue: &Queue, precision: Precision, len: usize) -> Result<Self> {
        Self::with_flags(
            queue,
            precision,
            &vec![0.0; len],
            MemFlags::new().read_write(),
        )
    }

    fn with_flags(
        queue: &Queue,
        precision: Precision,
        values: &[f64],
        flags: MemFlags,
    ) -> Result<Self> {
        let len = values.len().max(1);
        let buffer = match precision {
            Precision::F32 => RealBuffer::F32(
                Buffer::builder()
                    .queue(queue.clone())
                    .flags(flags)
                    .len(len)
                    .build()
                    .map_err(opencl)?,
            ),
            Precision::F64 => RealBuffer::F64(
                Buffer::builder()
                    .queue(queue.clone())
                    .flags(flags)
                    .len(len)
                    .build()
                    .map_err(opencl)?,
            ),
        };
        buffer.write(values)?;
        Ok(buffer)
    }

    pub(crate) fn len(&self) -> usize {
        match self {
            RealBuffer::F32(b) => b.len(),
            RealBuffer::F64(b) => b.len(),
        }
    }

    pub(crate) fn write(&self, values: &[f64]) -> Result<()> {
        if values.is_empty() {
            return Ok(());
        }
        match self {
            RealBuffer::F32(b) => {
                #[allow(clippy::cast_possible_truncation)]
                let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
                b.write(&v).len(v.len()).enq().map_err(opencl)
            }
            RealBuffer::F64(b) => b.write(values).len(values.len()).enq().map_err(opencl),
        }
    }

    /// Reads the whole buffer back as `f64`s.
    pub(crate) fn read(&self) -> Result<Vec<f64>> {
        match self {
            RealBuffer::F32(b) => {
                let mut v = vec![0.0f32; b.len()];
                b.read(&mut v).enq().map_err(opencl)?;
                Ok(v.into_iter().map(f64::from).collect())
            }
            RealBuffer::F64(b) => {
                let mut v = vec![0.0f64; b.len()];
                b.read(&mut v).enq().map_err(opencl)?;
                Ok(v)
            }
        }
    }

    pub(crate) fn push_arg<'b>(&'b self, builder: &mut ocl::builders::KernelBuilder<'b>) {
        match self {
            RealBuffer::F32(b) => builder.arg(b),
            RealBuffer::F64(b) => builder.arg(b),
        };
    }

    pub(crate) fn set_arg(&self, kernel: &Kernel, index: u32) -> Result<()> {
        match self {
            RealBuffer::F32(b) => kernel.set_arg(index, b),
            RealBuffer::F64(b) => kernel.set_arg(index, b),
        }
        .map_err(opencl)
    }
}

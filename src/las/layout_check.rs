//! Checks the sizes and counts a LAS/LAZ file announces against the file's length
//! before the `las` and `laz` crates read it, so that a corrupt header cannot make them
//! allocate without bound (they size buffers from these fields and abort the process
//! when the allocation fails).
//!
//! What is checked (everything else is left to the crates, which report it as an error):
//! - the offset to the point data and the first extended VLR (LAS 1.4) lie inside the
//!   file, and the EVLR's 64-bit length fits in what follows it (`las` allocates it);
//! - for LAZ, the chunk table: its offset lies inside the file, and its chunk count is
//!   at most one chunk per point record of compressed data (LASzip stores the first
//!   point of every chunk raw, so a chunk takes at least one record's bytes). `laz`
//!   reserves 16 bytes per announced chunk before decoding them: a flipped bit in the
//!   count asked for 44 GB (found by `tests/fuzz_readers.rs`, `mutated_laz_never_panics`);
//! - the decoded table: the chunks' compressed sizes sum to at most the compressed data,
//!   and no chunk holds more than [`MAX_LAZ_CHUNK_POINTS`] points (the parallel decoder
//!   allocates a chunk's decompressed records at once).

use crate::limits::MAX_LAZ_CHUNK_POINTS;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};

/// The LASzip VLR's user id and record id.
const LASZIP_USER_ID: &[u8] = b"laszip encoded";
const LASZIP_RECORD_ID: u16 = 22204;

/// Size of an extended VLR's header (LAS 1.4 R15, table 5).
const EVLR_HEADER_BYTES: u64 = 60;

/// `Err(why)` when the layout `file` announces does not fit in it (see the module
/// docs). A header that cannot be parsed at all passes: the `las` crate reports it.
pub fn check_layout(file: &File) -> Result<(), String> {
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut r = BufReader::new(file);
    r.seek(SeekFrom::Start(0)).map_err(|e| e.to_string())?;
    let Ok(header) = las::raw::Header::read_from(&mut r) else {
        return Ok(());
    };
    let data_start = u64::from(header.offset_to_point_data);
    if data_start > len {
        return Err(format!(
            "the header puts the point data at byte {data_start}, beyond the end of the \
             {len}-byte file (corrupt or truncated file?)"
        ));
    }
    if let Some(evlr) = header.evlr.filter(|e| e.number_of_evlrs > 0) {
        check_evlr(&mut r, evlr.start_of_first_evlr, len)?;
    }
    r.seek(SeekFrom::Start(u64::from(header.header_size)))
        .map_err(|e| e.to_string())?;
    let mut laszip = None;
    for _ in 0..header.number_of_variable_length_records {
        // Each VLR is at most 64 KiB and read only as far as the file goes.
        let Ok(vlr) = las::raw::Vlr::read_from(&mut r, false) else {
            break;
        };
        if vlr.user_id.starts_with(LASZIP_USER_ID) && vlr.record_id == LASZIP_RECORD_ID {
            laszip = Some(vlr.data);
            break;
        }
    }
    let Some(vlr) = laszip else {
        return Ok(());
    };
    let Ok(vlr) = laz::LazVlr::read_from(&vlr[..]) else {
        return Ok(());
    };
    check_chunk_table(&mut r, &vlr, data_start, len)
}

fn check_evlr<R: Read + Seek>(r: &mut R, start: u64, len: u64) -> Result<(), String> {
    if start.saturating_add(EVLR_HEADER_BYTES) > len {
        return Err(format!(
            "the header puts the first extended VLR at byte {start}, beyond the end of the \
             {len}-byte file (corrupt or truncated file?)"
        ));
    }
    // reserved (2), user id (16), record id (2), then the 64-bit record length.
    r.seek(SeekFrom::Start(start + 20))
        .map_err(|e| e.to_string())?;
    let length = read_u64(r)?;
    let room = len - start - EVLR_HEADER_BYTES;
    if length > room {
        return Err(format!(
            "the extended VLR at byte {start} announces {length} bytes, but only {room} \
             follow it in the file (corrupt or truncated file?)"
        ));
    }
    Ok(())
}

fn check_chunk_table<R: Read + Seek>(
    r: &mut R,
    vlr: &laz::LazVlr,
    data_start: u64,
    len: u64,
) -> Result<(), String> {
    if !vlr.uses_variable_size_chunks() && u64::from(vlr.chunk_size()) > MAX_LAZ_CHUNK_POINTS {
        return Err(format!(
            "the LASzip VLR announces chunks of {} points, above the {MAX_LAZ_CHUNK_POINTS} \
             this reader accepts (corrupt file?)",
            vlr.chunk_size()
        ));
    }
    let record = vlr.items_size().max(1);
    // Where laz looks for the table: the offset at the start of the point data, or, when
    // the writer could not go back to fill it in, the last 8 bytes of the file.
    if data_start + 8 > len {
        return Ok(()); // no point data at all: the las crate reports the truncation.
    }
    r.seek(SeekFrom::Start(data_start))
        .map_err(|e| e.to_string())?;
    let mut table = read_u64(r)? as i64;
    if table <= data_start as i64 {
        r.seek(SeekFrom::Start(len - 8))
            .map_err(|e| e.to_string())?;
        table = read_u64(r)? as i64;
        if table <= data_start as i64 {
            return Ok(()); // no chunk table: laz reports it.
        }
    }
    let table = table as u64;
    if table.saturating_add(8) > len {
        return Err(format!(
            "the LAZ chunk table is announced at byte {table}, beyond the end of the \
             {len}-byte file (corrupt or truncated file?)"
        ));
    }
    let compressed = table - (data_start + 8);
    r.seek(SeekFrom::Start(table + 4))
        .map_err(|e| e.to_string())?;
    let chunks = u64::from(read_u32(r)?);
    let most = compressed / record + 1;
    if chunks > most {
        return Err(format!(
            "the LAZ chunk table announces {chunks} chunks, but the {compressed} bytes of \
             compressed points hold at most {most} (each chunk starts with a {record}-byte \
             record; corrupt file?)"
        ));
    }
    r.seek(SeekFrom::Start(data_start))
        .map_err(|e| e.to_string())?;
    let entries = laz::laszip::ChunkTable::read_from(&mut *r, vlr)
        .map_err(|e| format!("cannot read the LAZ chunk table (corrupt file?): {e}"))?;
    let mut bytes = 0u64;
    for (i, entry) in entries.as_ref().iter().enumerate() {
        bytes = bytes.saturating_add(entry.byte_count);
        if entry.point_count > MAX_LAZ_CHUNK_POINTS {
            return Err(format!(
                "LAZ chunk {i} announces {} points, above the {MAX_LAZ_CHUNK_POINTS} this \
                 reader accepts (corrupt file?)",
                entry.point_count
            ));
        }
    }
    if bytes > compressed {
        return Err(format!(
            "the LAZ chunk table's chunks add up to {bytes} bytes, but the file holds \
             {compressed} bytes of compressed points (corrupt or truncated file?)"
        ));
    }
    Ok(())
}

fn read_u64<R: Read>(r: &mut R) -> Result<u64, String> {
    let mut b = [0u8; 8];
    r.read_exact(&mut b)
        .map_err(|e| format!("the file ends inside its header tables: {e}"))?;
    Ok(u64::from_le_bytes(b))
}

fn read_u32<R: Read>(r: &mut R) -> Result<u32, String> {
    let mut b = [0u8; 4];
    r.read_exact(&mut b)
        .map_err(|e| format!("the file ends inside its header tables: {e}"))?;
    Ok(u32::from_le_bytes(b))
}

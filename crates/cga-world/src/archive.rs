//! Rule packages: the files of a 7z or zip archive, as CityEngine writes
//! `.rpk` packages (`rules/*.cga`, compiled `bin/*.cgb`, `assets/`, and a
//! `.ws/` copy of workspace projects the rules import from).

use std::io::{self, Cursor, Read};
use std::path::Path;

use crate::MemoryWorld;

/// The files of an archive: `/`-separated paths inside it and their bytes;
/// folders are left out.
pub fn archive_files(bytes: &[u8]) -> io::Result<Vec<(String, Vec<u8>)>> {
    if bytes.starts_with(&[b'7', b'z', 0xBC, 0xAF, 0x27, 0x1C]) {
        seven_zip_files(bytes)
    } else if bytes.starts_with(b"PK") {
        zip_files(bytes)
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "not a rule package: neither a 7z nor a zip archive",
        ))
    }
}

fn invalid(e: impl std::fmt::Display) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, e.to_string())
}

fn seven_zip_files(bytes: &[u8]) -> io::Result<Vec<(String, Vec<u8>)>> {
    let mut reader =
        sevenz_rust2::ArchiveReader::new(Cursor::new(bytes), sevenz_rust2::Password::empty())
            .map_err(invalid)?;
    let mut files = Vec::new();
    reader
        .for_each_entries(|entry, data| {
            let mut content = Vec::new();
            // Solid archives decode in order: every entry's data is read,
            // also of folders (which have none).
            data.read_to_end(&mut content)?;
            if !entry.is_directory() {
                files.push((entry.name().replace('\\', "/"), content));
            }
            Ok(true)
        })
        .map_err(invalid)?;
    Ok(files)
}

fn zip_files(bytes: &[u8]) -> io::Result<Vec<(String, Vec<u8>)>> {
    let mut archive = zip::ZipArchive::new(Cursor::new(bytes)).map_err(invalid)?;
    let mut files = Vec::new();
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).map_err(invalid)?;
        if entry.is_dir() {
            continue;
        }
        let name = entry.name().replace('\\', "/");
        let mut content = Vec::with_capacity(entry.size() as usize);
        entry.read_to_end(&mut content)?;
        files.push((name, content));
    }
    Ok(files)
}

/// Sets the files of an archive in `world` under the folder `root` (the
/// package's own path, so that `/x/city.rpk/rules/a.cga` names a rule file
/// inside `/x/city.rpk`). Entries whose path would leave `root` (`..`,
/// absolute paths) are left out. Returns the paths set, relative to `root`.
pub fn mount_archive(world: &MemoryWorld, root: &Path, bytes: &[u8]) -> io::Result<Vec<String>> {
    let mut names = Vec::new();
    for (name, content) in archive_files(bytes)? {
        let inside = Path::new(&name)
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)));
        if !inside {
            continue;
        }
        world.set(root.join(&name), content);
        names.push(name);
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::World;

    /// A zip archive made with the zip crate's writer.
    fn zip_of(files: &[(&str, &str)]) -> Vec<u8> {
        let mut out = Cursor::new(Vec::new());
        {
            let mut w = zip::ZipWriter::new(&mut out);
            for (name, text) in files {
                w.start_file(*name, zip::write::SimpleFileOptions::default())
                    .unwrap();
                std::io::Write::write_all(&mut w, text.as_bytes()).unwrap();
            }
            w.finish().unwrap();
        }
        out.into_inner()
    }

    #[test]
    fn a_zip_package_mounts_under_its_own_path() {
        let bytes = zip_of(&[
            ("rules/a.cga", "Lot --> X."),
            ("assets/t.txt", "hello"),
            ("../evil.txt", "no"),
        ]);
        let world = MemoryWorld::new();
        let names = mount_archive(&world, Path::new("/p/city.rpk"), &bytes).unwrap();
        assert_eq!(names, vec!["rules/a.cga", "assets/t.txt"]);
        assert_eq!(
            world
                .read_text(Path::new("/p/city.rpk/rules/a.cga"))
                .unwrap(),
            "Lot --> X."
        );
        assert!(world.is_dir(Path::new("/p/city.rpk/assets")));
        assert!(!world.is_file(Path::new("/p/evil.txt")));
    }

    #[test]
    fn other_bytes_are_not_a_package() {
        let e = archive_files(b"Lot --> X.").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert!(archive_files(b"PK\x03\x04broken").is_err());
        assert!(archive_files(&[b'7', b'z', 0xBC, 0xAF, 0x27, 0x1C, 0, 4]).is_err());
    }
}

//! An MTL texture statement's options and file (`map_Kd -s 4 4 1 -bm 0.5 "floor tiles.png"`).
//! tobj keeps the whole text after the keyword as the file name, so a texture written with
//! options (Blender's OBJ exporter writes `-s` and `-o` for a scaled or moved mapping) or in
//! quotes was not found, and its material lost its texture with a warning. The options are
//! taken off here, the file left (spaces kept; quotes taken off), and the mapping's scale and
//! offset kept for the texture coordinates.

use glam::Vec2;

/// What an MTL `map_…` statement says.
#[derive(Debug, Clone, PartialEq)]
pub struct MapStatement {
    /// The file, as written (relative to the MTL's folder), without options or quotes.
    pub file: String,
    /// `-s u v`: the texture coordinates' scale (1, 1 where absent).
    pub scale: Vec2,
    /// `-o u v`: their offset, after the scale (0, 0 where absent).
    pub offset: Vec2,
}

impl MapStatement {
    /// Texture coordinates `uv` (as the OBJ gives them) mapped by the statement's scale and
    /// offset, as Blender's importer maps them: uv × scale + offset.
    pub fn map(&self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.offset
    }
}

/// How many arguments an option of the MTL specification takes (`-o`, `-s`, `-t`: one to
/// three numbers, read while they parse); `None` for a word that is no option.
fn arguments(option: &str) -> Option<(usize, usize)> {
    Some(match option {
        "-o" | "-s" | "-t" => (1, 3),
        "-mm" => (2, 2),
        "-blendu" | "-blendv" | "-boost" | "-texres" | "-clamp" | "-bm" | "-imfchan" | "-type"
        | "-cc" => (1, 1),
        _ => return None,
    })
}

/// Parses the text after a `map_…` keyword: options first, then the file.
pub fn parse(text: &str) -> MapStatement {
    let mut statement = MapStatement {
        file: String::new(),
        scale: Vec2::ONE,
        offset: Vec2::ZERO,
    };
    let mut rest = text.trim();
    loop {
        let (word, after) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
        let Some((least, most)) = arguments(word) else {
            break;
        };
        let mut after = after.trim_start();
        let mut values = Vec::new();
        while values.len() < most {
            let (arg, next) = after.split_once(char::is_whitespace).unwrap_or((after, ""));
            let number = arg.parse::<f32>().ok();
            if arg.is_empty() || (values.len() >= least && number.is_none()) {
                break;
            }
            values.push(number);
            after = next.trim_start();
        }
        let uv = |d: f32| {
            let at = |k: usize| values.get(k).copied().flatten();
            at(0).map(|u| Vec2::new(u, at(1).unwrap_or(d)))
        };
        match word {
            "-s" => statement.scale = uv(1.0).unwrap_or(Vec2::ONE),
            "-o" => statement.offset = uv(0.0).unwrap_or(Vec2::ZERO),
            _ => {}
        }
        rest = after;
    }
    let file = rest.trim();
    let unquoted = (file.len() >= 2 && file.starts_with('"') && file.ends_with('"'))
        .then(|| &file[1..file.len() - 1]);
    statement.file = unquoted.unwrap_or(file).to_string();
    statement
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_are_taken_off_and_the_file_kept() {
        let p = parse("textures\\sponza_floor_a_diff.tga");
        assert_eq!(p.file, "textures\\sponza_floor_a_diff.tga");
        assert_eq!((p.scale, p.offset), (Vec2::ONE, Vec2::ZERO));
        // Blender's exporter with a scaled, moved mapping.
        let p = parse("-o 0.25 0.5 0 -s 4 2 1 tiles.png");
        assert_eq!(p.file, "tiles.png");
        assert_eq!(
            (p.scale, p.offset),
            (Vec2::new(4.0, 2.0), Vec2::new(0.25, 0.5))
        );
        assert_eq!(p.map(Vec2::new(0.5, 0.5)), Vec2::new(2.25, 1.5));
        // One number: u alone, v as unscaled.
        let p = parse("-s 3 wall.png");
        assert_eq!(
            (p.file.as_str(), p.scale),
            ("wall.png", Vec2::new(3.0, 1.0))
        );
        // Options of other kinds, a file name with spaces, in quotes.
        let p = parse("-bm 0.5 -clamp on -mm 0 1 -imfchan l \"my floor.png\"");
        assert_eq!(p.file, "my floor.png");
        assert_eq!(parse("my floor.png").file, "my floor.png");
        // A file whose name starts with a dash is no option.
        assert_eq!(parse("-dark.png").file, "-dark.png");
    }
}

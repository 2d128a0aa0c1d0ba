fn main() {
    println!("smoothtrace");
}
